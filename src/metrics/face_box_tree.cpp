// The build of FaceBoxTree (face_box_tree.h).
#include "metrics/face_box_tree.h"

#include "numerics/vertex_ordering.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/parallel_reduce.h>
#include <tbb/parallel_sort.h>

#include <bit>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace vertexflow {

namespace {

// Ranges of at least this many faces build their two halves as parallel tasks.
constexpr std::int64_t kParallelFrom = 16384;

// The float just below (above) x, or x itself when it is a float: a float box that contains the
// double one.
float round_down(double x) {
  const auto f = static_cast<float>(x);
  return static_cast<double>(f) > x ? std::nextafter(f, -std::numeric_limits<float>::infinity()) : f;
}
float round_up(double x) {
  const auto f = static_cast<float>(x);
  return static_cast<double>(f) < x ? std::nextafter(f, std::numeric_limits<float>::infinity()) : f;
}

struct Box {
  Eigen::Array3d lo = Eigen::Array3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Array3d hi = Eigen::Array3d::Constant(-std::numeric_limits<double>::infinity());
  void add(const Box& b) {
    lo = lo.min(b.lo);
    hi = hi.max(b.hi);
  }
};

}  // namespace

// The build: Morton codes of the face centroids, sorted (ties by face), then two passes over the
// binary radix tree of the codes. The first counts each subtree's inner nodes, so that the second
// can give every node its place in depth-first order (a node's first child next to it) while
// both halves of a range are built at once.
struct FaceBoxTreeBuilder {
  const Vertices& V;
  const Faces& F;
  FaceBoxTree& tree;
  std::vector<std::uint64_t> codes;    // sorted, parallel to tree.order_
  std::vector<std::int32_t> inner_at;  // inner nodes below the node split at position s, by s

  // Where [first, last) splits: before the first code with the highest bit in which the range's
  // first and last codes differ; the middle when all its codes are equal.
  [[nodiscard]] std::int64_t split(std::int64_t first, std::int64_t last) const {
    const std::uint64_t a = codes[static_cast<std::size_t>(first)], b = codes[static_cast<std::size_t>(last - 1)];
    if (a == b) return first + (last - first) / 2;
    const std::uint64_t bit = std::uint64_t{1} << (63 - std::countl_zero(a ^ b));
    const auto it = std::partition_point(codes.begin() + first, codes.begin() + last,
                                         [bit](std::uint64_t c) { return (c & bit) == 0; });
    return it - codes.begin();
  }

  // Inner nodes of the subtree over [first, last) (0 for a leaf); records each split's count.
  std::int32_t count(std::int64_t first, std::int64_t last, int depth) {
    if (last - first <= FaceBoxTree::kLeafFaces) return 0;
    if (depth > FaceBoxTree::kMaxDepth - 2) throw std::logic_error("FaceBoxTree: too deep");
    const std::int64_t s = split(first, last);
    std::int32_t left = 0, right = 0;
    if (last - first >= kParallelFrom)
      tbb::parallel_invoke([&] { left = count(first, s, depth + 1); }, [&] { right = count(s, last, depth + 1); });
    else {
      left = count(first, s, depth + 1);
      right = count(s, last, depth + 1);
    }
    return inner_at[static_cast<std::size_t>(s)] = 1 + left + right;
  }

  Box face_box(Index f) const {
    Box box;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Array3d p = V.row(F(f, k)).transpose().array();
      box.lo = box.lo.min(p);
      box.hi = box.hi.max(p);
    }
    return box;
  }

  // Fills child k of `parent` with the subtree over [first, last), whose inner nodes (if any)
  // take the places from `place` on; returns its box.
  Box build(std::int64_t first, std::int64_t last, std::int32_t place, FaceBoxTree::Node& parent, int k) {
    Box box;
    if (last - first <= FaceBoxTree::kLeafFaces) {
      for (std::int64_t i = first; i < last; ++i) box.add(face_box(tree.order_[static_cast<std::size_t>(i)]));
      parent.index[k] = static_cast<std::int32_t>(first);
      parent.count[k] = static_cast<std::int32_t>(last - first);
    } else {
      const std::int64_t s = split(first, last);
      FaceBoxTree::Node& node = tree.nodes_[static_cast<std::size_t>(place)];
      const std::int32_t left_inner =
          s - first > FaceBoxTree::kLeafFaces ? inner_at[static_cast<std::size_t>(split(first, s))] : 0;
      Box left, right;
      const auto build_left = [&] { left = build(first, s, place + 1, node, 0); };
      const auto build_right = [&] { right = build(s, last, place + 1 + left_inner, node, 1); };
      if (last - first >= kParallelFrom)
        tbb::parallel_invoke(build_left, build_right);
      else {
        build_left();
        build_right();
      }
      box = left;
      box.add(right);
      parent.index[k] = place;
      parent.count[k] = 0;
    }
    for (int a = 0; a < 3; ++a) {
      parent.lo[k][a] = round_down(box.lo[a]);
      parent.hi[k][a] = round_up(box.hi[a]);
    }
    return box;
  }
};

FaceBoxTree::FaceBoxTree(const Vertices& V, const Faces& F) {
  const auto nf = static_cast<std::int64_t>(F.rows());
  // An empty second child of the root: an inverted box, never within any bound.
  root_.lo[1] = {std::numeric_limits<float>::infinity(), std::numeric_limits<float>::infinity(),
                 std::numeric_limits<float>::infinity()};
  root_.hi[1] = {-std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity(),
                 -std::numeric_limits<float>::infinity()};
  root_.index[1] = 0;
  root_.count[1] = 0;
  root_.index[0] = 0;
  root_.count[0] = 0;
  if (nf == 0) return;

  // The centroids' box (min and max do not depend on the order of the reduction).
  const auto centroid = [&](std::int64_t f) -> Eigen::Array3d {
    const auto i = static_cast<Index>(f);
    return ((V.row(F(i, 0)) + V.row(F(i, 1)) + V.row(F(i, 2))) / 3.0).transpose().array();
  };
  const Box bounds = tbb::parallel_reduce(
      tbb::blocked_range<std::int64_t>(0, nf, 65536), Box{},
      [&](const tbb::blocked_range<std::int64_t>& r, Box box) {
        for (std::int64_t f = r.begin(); f != r.end(); ++f) {
          const Eigen::Array3d c = centroid(f);
          box.lo = box.lo.min(c);
          box.hi = box.hi.max(c);
        }
        return box;
      },
      [](Box a, const Box& b) {
        a.add(b);
        return a;
      });
  const Eigen::Array3d scale = (bounds.hi - bounds.lo).max(1e-300).inverse() * 2097151.0;
  struct Key {
    std::uint64_t code;
    Index face;
    bool operator<(const Key& other) const { return code < other.code || (code == other.code && face < other.face); }
  };
  std::vector<Key> keys(static_cast<std::size_t>(nf));
  tbb::parallel_for(tbb::blocked_range<std::int64_t>(0, nf, 4096), [&](const tbb::blocked_range<std::int64_t>& r) {
    for (std::int64_t f = r.begin(); f != r.end(); ++f) {
      const Eigen::Array3d t = (centroid(f) - bounds.lo) * scale;
      keys[static_cast<std::size_t>(f)] = {morton_code_of_cells(t.x(), t.y(), t.z()), static_cast<Index>(f)};
    }
  });
  // The keys are unique (each carries its face), so the order is the same for any thread count.
  tbb::parallel_sort(keys.begin(), keys.end());

  FaceBoxTreeBuilder builder{V, F, *this, std::vector<std::uint64_t>(static_cast<std::size_t>(nf)),
                             std::vector<std::int32_t>(static_cast<std::size_t>(nf), 0)};
  order_.resize(static_cast<std::size_t>(nf));
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, keys.size(), 65536),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t i = r.begin(); i != r.end(); ++i) {
                        builder.codes[i] = keys[i].code;
                        order_[i] = keys[i].face;
                      }
                    });
  std::vector<Key>().swap(keys);
  nodes_.resize(static_cast<std::size_t>(builder.count(0, nf, 0)));
  builder.build(0, nf, 0, root_, 0);
}

}  // namespace vertexflow
