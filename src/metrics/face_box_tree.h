// Internal: a bounding-box hierarchy over a mesh's faces, the search structure behind
// DistanceQuery (include/vertexflow/distance.h).
//
// Why ours and not a library's: CGAL's AABB_tree builds on one thread (at 19.5M faces each of the
// report's two trees took 23-25 s of CPU, a fifth of the report's time) and holds a 64-byte node
// per face; Embree's rtcPointQuery answers faster but culls in float and reserves hundreds of MB
// of address space per build, which breaks the memory refusal under `ulimit -v` (docs/lod.md).
// This tree is a linear BVH: faces sorted by the Morton code of their centroid, split top-down
// where the codes' highest differing bit changes (a binary radix tree), built on all threads.
//
// Layout: a node holds both children's boxes (48 bytes, floats rounded outward, so that each box
// contains its faces' double-precision boxes), so a visit reads one 64-byte line and decides for
// both children. Leaves are runs of at most kLeafFaces faces in the sorted order. About 16 bytes
// of nodes and 4 of face order per face. The tree depends only on (V, F): the same for any
// number of threads.
#pragma once

#include "vertexflow/mesh.h"

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace vertexflow {

class FaceBoxTree {
 public:
  /// At most this many faces in a leaf.
  static constexpr int kLeafFaces = 4;
  /// See search().
  static constexpr double kRoundingSlack = 1 + 1e-12;

  FaceBoxTree() = default;
  /// Builds the tree over the faces of (V, F), which it does not keep (searches read nothing
  /// from them). F must index inside V (not checked here).
  FaceBoxTree(const Vertices& V, const Faces& F);

  /// Calls visit(f) for each face f whose box may lie within squared distance `bound` of q,
  /// nearer boxes first; `visit` may lower `bound` (to the squared distance of the best answer
  /// so far), which prunes the rest. A box at `bound` is visited, and so is one beyond it by
  /// less than a relative 1e-12 (rounding: a face's distance and its box's are computed apart),
  /// so a caller that breaks ties between equally close faces sees all of them.
  template <class Visit>
  void search(const double q[3], double& bound, Visit&& visit) const;

  [[nodiscard]] std::size_t memory_bytes() const {
    return nodes_.capacity() * sizeof(Node) + order_.capacity() * sizeof(Index);
  }

 private:
  // A child: an inner node (count 0, index into nodes_) or a leaf (count faces from order_[index]).
  struct Node {
    std::array<float, 3> lo[2];
    std::array<float, 3> hi[2];
    std::int32_t index[2];
    std::int32_t count[2];
  };
  static_assert(sizeof(Node) == 64);

  // Squared distance from q to child k's box (0 inside).
  static double box_distance(const double q[3], const Node& node, int k) {
    double d2 = 0;
    for (int a = 0; a < 3; ++a) {
      const double below = static_cast<double>(node.lo[k][a]) - q[a];
      const double above = q[a] - static_cast<double>(node.hi[k][a]);
      const double d = std::max(0.0, std::max(below, above));
      d2 += d * d;
    }
    return d2;
  }

  // Depth bound: at most 63 radix splits (21-bit codes per axis), then halvings of runs of equal
  // codes (at most 31 for 2^31 faces); the stack holds one pending sibling per level.
  static constexpr int kMaxDepth = 128;

  std::vector<Node> nodes_;
  std::vector<Index> order_;  // faces in tree order
  Node root_{};               // child 0 is the root (child 1 empty), so the search starts uniformly
  friend struct FaceBoxTreeBuilder;
};

template <class Visit>
void FaceBoxTree::search(const double q[3], double& bound, Visit&& visit) const {
  struct Pending {
    std::int32_t index, count;
    double d2;
  };
  if (root_.count[0] == 0 && nodes_.empty()) return;  // no faces
  std::array<Pending, kMaxDepth + 2> stack;
  int top = 0;
  stack[top++] = {root_.index[0], root_.count[0], box_distance(q, root_, 0)};
  while (top > 0) {
    const Pending p = stack[--top];
    if (p.d2 > bound * kRoundingSlack) continue;
    if (p.count > 0) {
      for (std::int32_t k = 0; k < p.count; ++k) visit(order_[static_cast<std::size_t>(p.index + k)]);
      continue;
    }
    const Node& node = nodes_[static_cast<std::size_t>(p.index)];
    Pending near{node.index[0], node.count[0], box_distance(q, node, 0)};
    Pending far{node.index[1], node.count[1], box_distance(q, node, 1)};
    if (far.d2 < near.d2) std::swap(near, far);
    if (far.d2 <= bound * kRoundingSlack) stack[top++] = far;
    if (near.d2 <= bound * kRoundingSlack) stack[top++] = near;
  }
}

}  // namespace vertexflow
