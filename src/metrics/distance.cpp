// Mesh-to-mesh distances (include/vertexflow/distance.h): CGAL's AABB tree for the closest
// points, TBB for the parallel queries.
#include "vertexflow/distance.h"

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Simple_cartesian.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/parallel_sort.h>
#include <tbb/partitioner.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <mutex>
#include <numeric>
#include <random>
#include <stdexcept>
#include <string>

namespace vertexflow {
namespace {

// Constructions (the closest point) are in doubles either way; Simple_cartesian skips the
// interval filtering of the exact-predicates kernels, which buys nothing here.
using Kernel = CGAL::Simple_cartesian<double>;
using Triangle = Kernel::Triangle_3;
using TriangleIterator = std::vector<Triangle>::const_iterator;
// CacheDatum false: a primitive is an iterator into DistanceQuery's triangle array, not a copy
// of its triangle. The tree's build sorts primitives, and with the copies (80 bytes each) it
// took twice as long: 1.52 s against 0.75 s for 1.1M triangles (bunny.off subdivided). Queries
// read the triangle from the contiguous array instead, about 10% slower (bench_compare, with
// the k-d tree below removed too: build 319 -> 174 ms, 200k queries 374 -> 415 ms, the whole
// two-sided distance 1307 -> 1144 ms).
using Primitive = CGAL::AABB_triangle_primitive<Kernel, TriangleIterator, CGAL::Tag_false>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<Kernel, Primitive>>;

// Squared distance from p to an axis-aligned box (0 inside).
inline double squared_distance_to_box(const Kernel::Point_3& p, const CGAL::Bbox_3& box) {
  const double dx = std::max(0.0, std::max(box.xmin() - p.x(), p.x() - box.xmax()));
  const double dy = std::max(0.0, std::max(box.ymin() - p.y(), p.y() - box.ymax()));
  const double dz = std::max(0.0, std::max(box.zmin() - p.z(), p.z() - box.zmax()));
  return dx * dx + dy * dy + dz * dz;
}

// Closest-point search over CGAL's tree with CGAL's point-triangle projection, driven by
// AABB_tree::traversal_with_priority (marked internal, present throughout CGAL 5.x). It finds
// the same distance as AABB_tree::closest_point_and_primitive (where two triangles are equally
// close it may name the other one) with less work: CGAL's own traits visit both children in a
// fixed order, test each box by constructing a sphere, and project every triangle of a leaf
// pair; here the nearer child is visited first, boxes are tested by their squared distance,
// and a triangle whose bounding box is already further than the best point so far is not
// projected. On the 100k-vertex benchmark (bench/bench_compare.cpp) projections took 42% and
// the traversal 40% of CGAL's query time; these traits halve it.
class ClosestPointTraits {
 public:
  using Priority = double;  // minus the squared distance to the box: nearer first

  ClosestPointTraits(const Kernel::Point_3& query, const Tree::Point_and_primitive_id& hint)
      : best_(hint), best_d2_(CGAL::squared_distance(query, hint.first)) {}

  [[nodiscard]] bool go_further() const { return true; }

  void intersection(const Kernel::Point_3& query, const Primitive& primitive) {
    const Triangle& t = primitive.datum();
    if (squared_distance_to_box(query, t.bbox()) >= best_d2_) return;
    const Kernel::Point_3 closest = Kernel().construct_projected_point_3_object()(t, query);
    const double d2 = CGAL::squared_distance(query, closest);
    if (d2 < best_d2_) {
      best_ = {closest, primitive.id()};
      best_d2_ = d2;
    }
  }

  template <class Node>
  [[nodiscard]] bool do_intersect(const Kernel::Point_3& query, const Node& node) const {
    return squared_distance_to_box(query, node.bbox()) < best_d2_;
  }

  template <class Node>
  [[nodiscard]] std::pair<bool, Priority> do_intersect_with_priority(const Kernel::Point_3& query,
                                                                     const Node& node) const {
    const double d2 = squared_distance_to_box(query, node.bbox());
    return {d2 < best_d2_, -d2};
  }

  [[nodiscard]] const Tree::Point_and_primitive_id& result() const { return best_; }

 private:
  Tree::Point_and_primitive_id best_;
  double best_d2_;
};

// Queries run in blocks of this many points. A block's first query starts from the guess of
// the tree's k-d tree, each later one from the triangle of the previous answer (consecutive
// points are close: samples are sorted by face, edges by vertex); fixed blocks make the answers
// independent of how TBB schedules them.
constexpr std::size_t kQueryBlock = 256;

Kernel::Point_3 to_cgal(const Eigen::Vector3d& p) {
  return {p.x(), p.y(), p.z()};
}
Eigen::Vector3d to_eigen(const Kernel::Point_3& p) {
  return {p.x(), p.y(), p.z()};
}

void check_indices(const Vertices& V, const Faces& F, const char* what) {
  if (F.size() > 0 && (F.minCoeff() < 0 || F.maxCoeff() >= V.rows()))
    throw std::invalid_argument(std::string(what) + ": a face index is outside the " + std::to_string(V.rows()) +
                                " vertices");
}

// Barycentric coordinates of q (a point of triangle abc, up to rounding) by least squares in
// the triangle's plane, clamped to the triangle. A degenerate triangle gives its corner closest
// to q.
Eigen::Vector3d barycentric(const Eigen::Vector3d& q, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                            const Eigen::Vector3d& c) {
  const Eigen::Vector3d e0 = b - a, e1 = c - a, r = q - a;
  const double d00 = e0.dot(e0), d01 = e0.dot(e1), d11 = e1.dot(e1), d20 = r.dot(e0), d21 = r.dot(e1);
  const double denominator = d00 * d11 - d01 * d01;
  Eigen::Vector3d w;
  if (denominator > 1e-14 * d00 * d11) {
    const double v = (d11 * d20 - d01 * d21) / denominator;
    const double u = (d00 * d21 - d01 * d20) / denominator;
    w = {1.0 - v - u, v, u};
    w = w.cwiseMax(0.0);
    const double sum = w.sum();
    if (sum > 0) return w / sum;
  }
  const double da = (q - a).squaredNorm(), db = (q - b).squaredNorm(), dc = (q - c).squaredNorm();
  if (da <= db && da <= dc) return {1, 0, 0};
  return db <= dc ? Eigen::Vector3d(0, 1, 0) : Eigen::Vector3d(0, 0, 1);
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Sampling

SurfaceSamples sample_surface(const Vertices& V, const Faces& F, const SamplingOptions& options) {
  if (options.samples < 0) throw std::invalid_argument("sample_surface: negative sample count");
  check_indices(V, F, "sample_surface");
  const Index nf = static_cast<Index>(F.rows());

  // Cumulative face areas; a face is drawn when a uniform number in [0, total) falls in its
  // interval, so zero-area faces are never drawn.
  std::vector<double> cumulative(static_cast<std::size_t>(nf));
  double total = 0;
  for (Index f = 0; f < nf; ++f) cumulative[static_cast<std::size_t>(f)] = total += face_area(V, F, f);

  SurfaceSamples s;
  s.num_area_samples = total > 0 ? options.samples : 0;
  // Each undirected edge once: sort the keys (smaller vertex, larger vertex) of all face sides.
  // (build_topology has the edges too, but refuses non-manifold and repeated-vertex faces,
  // which distances must accept.)
  std::vector<std::uint64_t> edges;
  if (options.edge_midpoints) {
    edges.reserve(3 * static_cast<std::size_t>(nf));
    for (Index f = 0; f < nf; ++f) {
      for (int k = 0; k < 3; ++k) {
        const auto i = static_cast<std::uint32_t>(F(f, k)), j = static_cast<std::uint32_t>(F(f, (k + 1) % 3));
        if (i != j) edges.push_back(std::uint64_t{std::min(i, j)} << 32 | std::max(i, j));
      }
    }
    tbb::parallel_sort(edges.begin(), edges.end());
    edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  }
  s.num_vertices = options.vertices ? static_cast<Index>(V.rows()) : 0;
  s.num_edge_midpoints = static_cast<Index>(edges.size());
  s.points.resize(std::int64_t{s.num_area_samples} + s.num_vertices + s.num_edge_midpoints, 3);

  if (s.num_area_samples > 0) {
    // One sequential stream, so the samples do not depend on the thread count. Doubles in
    // [0, 1) from the top 53 bits: mt19937_64's output is fully specified by the standard,
    // std::uniform_real_distribution's is not.
    std::mt19937_64 random(options.seed);
    const auto uniform = [&random] { return static_cast<double>(random() >> 11) * 0x1.0p-53; };
    const auto n = static_cast<std::size_t>(s.num_area_samples);
    std::vector<Index> face(n);
    std::vector<double> r1(n), r2(n);
    std::vector<Index> offset(static_cast<std::size_t>(nf) + 1, 0);
    for (std::size_t i = 0; i < n; ++i) {
      const double u = uniform() * total;
      const auto it = std::upper_bound(cumulative.begin(), cumulative.end(), u);
      // u < total = cumulative.back() unless rounding made them equal: take the last face of
      // non-zero area then.
      auto f = static_cast<Index>(it - cumulative.begin());
      if (f == nf)
        f = static_cast<Index>(std::lower_bound(cumulative.begin(), cumulative.end(), total) - cumulative.begin());
      face[i] = f;
      r1[i] = uniform();
      r2[i] = uniform();
      ++offset[static_cast<std::size_t>(f) + 1];
    }
    // Counting sort by face (stable, so the order within a face is the order of drawing).
    for (Index f = 0; f < nf; ++f) offset[static_cast<std::size_t>(f) + 1] += offset[static_cast<std::size_t>(f)];
    for (std::size_t i = 0; i < n; ++i) {
      const Index f = face[i];
      double a = r1[i], b = r2[i];
      if (a + b > 1) {  // reflect the far half of the unit square onto the triangle: uniform
        a = 1 - a;
        b = 1 - b;
      }
      const Eigen::RowVector3d p0 = V.row(F(f, 0));
      s.points.row(offset[static_cast<std::size_t>(f)]++) = p0 + a * (V.row(F(f, 1)) - p0) + b * (V.row(F(f, 2)) - p0);
    }
  }
  if (s.num_vertices > 0) s.points.middleRows(s.num_area_samples, s.num_vertices) = V;
  const std::int64_t first_midpoint = std::int64_t{s.num_area_samples} + s.num_vertices;
  for (std::size_t e = 0; e < edges.size(); ++e) {
    const auto i = static_cast<Index>(edges[e] >> 32), j = static_cast<Index>(edges[e] & 0xffffffffu);
    s.points.row(first_midpoint + static_cast<std::int64_t>(e)) = 0.5 * (V.row(i) + V.row(j));
  }
  return s;
}

// ---------------------------------------------------------------------------------------------
// Closest points

// Meshes with at least this many faces get two trees, over the two halves of the faces split at
// the median of their centroids along the longest side of the bounding box, built in parallel:
// CGAL builds a tree on one thread. On 1.1M faces (bunny.off subdivided) one tree took 0.75 s,
// two halves 0.53 s on 2 cores; a query searches the tree whose box is nearer first, and the
// other is then mostly pruned at its root. The split does not depend on the thread count.
constexpr Index kTwoTreesFrom = 200000;

struct DistanceQuery::Impl {
  Vertices V;
  Faces F;
  std::vector<Triangle> triangles;  // in tree order: face_of[k] is the face of triangles[k]
  std::vector<Index> face_of;       // empty: triangles[k] is face k
  std::vector<Tree> trees;          // over consecutive ranges of triangles

  Tree::Point_and_primitive_id closest(const Kernel::Point_3& q, const Tree::Point_and_primitive_id& hint) const {
    ClosestPointTraits traits(q, hint);
    if (trees.size() == 1) {
      trees[0].traversal_with_priority(q, traits);
    } else {
      const bool second_first =
          squared_distance_to_box(q, trees[1].bbox()) < squared_distance_to_box(q, trees[0].bbox());
      trees[second_first ? 1 : 0].traversal_with_priority(q, traits);
      trees[second_first ? 0 : 1].traversal_with_priority(q, traits);
    }
    return traits.result();
  }
  [[nodiscard]] Tree::Point_and_primitive_id any_hint(const Kernel::Point_3& q) const { return trees[0].best_hint(q); }
  [[nodiscard]] Index face(TriangleIterator t) const {
    const auto k = static_cast<std::size_t>(t - triangles.begin());
    return face_of.empty() ? static_cast<Index>(k) : face_of[k];
  }

  // Runs fn(point index, query point, CGAL answer) for the rows [first, last) of P, in fixed
  // blocks (see kQueryBlock). With skip_at_most >= 0, a point whose first guess is already
  // within that squared distance is skipped (its distance cannot exceed it): for maxima.
  template <class Fn>
  void for_each_closest(const Vertices& P, std::size_t first, std::size_t last, double skip_at_most, Fn&& fn) const {
    const std::size_t blocks = (last - first + kQueryBlock - 1) / kQueryBlock;
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, blocks, 1),
        [&](const tbb::blocked_range<std::size_t>& range) {
          for (std::size_t block = range.begin(); block != range.end(); ++block) {
            const std::size_t begin = first + block * kQueryBlock, end = std::min(last, begin + kQueryBlock);
            Tree::Point_and_primitive_id hint;
            for (std::size_t i = begin; i < end; ++i) {
              const Kernel::Point_3 q = to_cgal(P.row(static_cast<Eigen::Index>(i)).transpose());
              if (i == begin) {
                hint = any_hint(q);
              } else {
                // Start from the closest point of the previous answer's triangle: a tighter
                // first bound than the previous closest point itself.
                hint.first = Kernel().construct_projected_point_3_object()(*hint.second, q);
              }
              if (skip_at_most >= 0 && CGAL::squared_distance(q, hint.first) <= skip_at_most) continue;
              hint = closest(q, hint);
              fn(i, q, hint);
            }
          }
        },
        tbb::simple_partitioner());
  }

  template <class Fn>
  void for_each_closest(const Vertices& P, Fn&& fn) const {
    for_each_closest(P, 0, static_cast<std::size_t>(P.rows()), -1.0, std::forward<Fn>(fn));
  }

  ClosestPoint make_answer(const Kernel::Point_3& q, const Tree::Point_and_primitive_id& answer) const {
    ClosestPoint c;
    c.point = to_eigen(answer.first);
    c.squared_distance = CGAL::squared_distance(q, answer.first);
    c.face = face(answer.second);
    c.barycentric = barycentric(c.point, V.row(F(c.face, 0)), V.row(F(c.face, 1)), V.row(F(c.face, 2)));
    return c;
  }
};

namespace {

// distance_trees_built: trees by face count.
std::mutex trees_mutex;
std::map<Index, std::uint64_t>& trees_by_size() {
  static std::map<Index, std::uint64_t> trees;
  return trees;
}

}  // namespace

std::uint64_t distance_trees_built(Index num_faces) {
  const std::lock_guard lock(trees_mutex);
  const auto it = trees_by_size().find(num_faces);
  return it == trees_by_size().end() ? 0 : it->second;
}

DistanceQuery::DistanceQuery(const Vertices& V, const Faces& F) : impl_(std::make_unique<Impl>()) {
  if (F.rows() == 0) throw std::invalid_argument("DistanceQuery: the mesh has no faces");
  {
    const std::lock_guard lock(trees_mutex);
    ++trees_by_size()[static_cast<Index>(F.rows())];
  }
  check_indices(V, F, "DistanceQuery");
  impl_->V = V;
  impl_->F = F;
  const Index nf = static_cast<Index>(F.rows());
  const auto make_triangle = [&](Index f) {
    return Triangle(to_cgal(V.row(F(f, 0))), to_cgal(V.row(F(f, 1))), to_cgal(V.row(F(f, 2))));
  };
  impl_->triangles.resize(static_cast<std::size_t>(nf));
  Index first_half = nf;
  if (nf >= kTwoTreesFrom) {
    // The median split (kTwoTreesFrom), ties broken by face index.
    const Eigen::RowVector3d low = V.colwise().minCoeff(), high = V.colwise().maxCoeff();
    Eigen::Index axis = 0;
    (high - low).maxCoeff(&axis);
    std::vector<double> key(static_cast<std::size_t>(nf));
    tbb::parallel_for(tbb::blocked_range<Index>(0, nf), [&](const tbb::blocked_range<Index>& r) {
      for (Index f = r.begin(); f != r.end(); ++f)
        key[static_cast<std::size_t>(f)] = V(F(f, 0), axis) + V(F(f, 1), axis) + V(F(f, 2), axis);
    });
    impl_->face_of.resize(static_cast<std::size_t>(nf));
    std::iota(impl_->face_of.begin(), impl_->face_of.end(), Index{0});
    first_half = nf / 2;
    std::nth_element(impl_->face_of.begin(), impl_->face_of.begin() + first_half, impl_->face_of.end(),
                     [&](Index a, Index b) {
                       const double ka = key[static_cast<std::size_t>(a)], kb = key[static_cast<std::size_t>(b)];
                       return ka < kb || (ka == kb && a < b);
                     });
  }
  tbb::parallel_for(tbb::blocked_range<Index>(0, nf), [&](const tbb::blocked_range<Index>& r) {
    for (Index k = r.begin(); k != r.end(); ++k)
      impl_->triangles[static_cast<std::size_t>(k)] =
          make_triangle(impl_->face_of.empty() ? k : impl_->face_of[static_cast<std::size_t>(k)]);
  });
  const auto begin = impl_->triangles.cbegin();
  const auto split = begin + first_half;
  impl_->trees.resize(split == impl_->triangles.cend() ? 1 : 2);
  // No k-d tree of reference points for hints (CGAL builds one by default, lazily on the first
  // query, serialising the threads): queries run in blocks where each point starts from the
  // previous point's answer, so only a block's first query would use it. It cost 0.8 s of the
  // 2.3 s build for 1.1M triangles.
  const auto build = [](Tree& tree, TriangleIterator first, TriangleIterator last) {
    tree.insert(first, last);
    tree.do_not_accelerate_distance_queries();
    tree.build();
  };
  if (impl_->trees.size() == 1) {
    build(impl_->trees[0], begin, impl_->triangles.cend());
  } else {
    tbb::parallel_invoke([&] { build(impl_->trees[0], begin, split); },
                         [&] { build(impl_->trees[1], split, impl_->triangles.cend()); });
  }
}

DistanceQuery::~DistanceQuery() = default;
DistanceQuery::DistanceQuery(DistanceQuery&&) noexcept = default;
DistanceQuery& DistanceQuery::operator=(DistanceQuery&&) noexcept = default;

const Vertices& DistanceQuery::vertices() const {
  return impl_->V;
}
const Faces& DistanceQuery::faces() const {
  return impl_->F;
}

ClosestPoint DistanceQuery::closest_point(const Eigen::Vector3d& p) const {
  const Kernel::Point_3 q = to_cgal(p);
  return impl_->make_answer(q, impl_->closest(q, impl_->any_hint(q)));
}

std::vector<ClosestPoint> DistanceQuery::closest_points(const Vertices& P) const {
  std::vector<ClosestPoint> out(static_cast<std::size_t>(P.rows()));
  impl_->for_each_closest(P, [&](std::size_t i, const Kernel::Point_3& q, const Tree::Point_and_primitive_id& a) {
    out[i] = impl_->make_answer(q, a);
  });
  return out;
}

Eigen::VectorXd DistanceQuery::squared_distances(const Vertices& P) const {
  Eigen::VectorXd out(P.rows());
  impl_->for_each_closest(P, [&](std::size_t i, const Kernel::Point_3& q, const Tree::Point_and_primitive_id& a) {
    out[static_cast<Eigen::Index>(i)] = CGAL::squared_distance(q, a.first);
  });
  return out;
}

double DistanceQuery::max_squared_distance(const Vertices& P, Index first_row, double at_least) const {
  if (first_row < 0 || first_row > P.rows())
    throw std::invalid_argument("max_squared_distance: first row out of range");
  const auto first = static_cast<std::size_t>(first_row), last = static_cast<std::size_t>(P.rows());
  // One slot per block (a block runs on one thread at a time); the maximum does not depend on
  // the order of the slots.
  std::vector<double> block_max((last - first + kQueryBlock - 1) / kQueryBlock, at_least);
  impl_->for_each_closest(P, first, last, std::max(at_least, 0.0),
                          [&](std::size_t i, const Kernel::Point_3& q, const Tree::Point_and_primitive_id& a) {
                            double& slot = block_max[(i - first) / kQueryBlock];
                            slot = std::max(slot, CGAL::squared_distance(q, a.first));
                          });
  return std::accumulate(block_max.begin(), block_max.end(), at_least,
                         [](double a, double b) { return std::max(a, b); });
}

// ---------------------------------------------------------------------------------------------
// Statistics

DistanceStats one_sided_distance(const SurfaceSamples& a, const DistanceQuery& b) {
  DistanceStats s;
  s.points = static_cast<Index>(a.points.rows());
  if (a.points.rows() == 0) return s;
  if (a.num_area_samples == 0) {  // no area samples: every figure over all points
    const Eigen::VectorXd d2 = b.squared_distances(a.points);
    s.mean = d2.cwiseSqrt().mean();
    s.rms = std::sqrt(d2.mean());
    s.max = std::sqrt(d2.maxCoeff());
    return s;
  }
  // Mean and RMS from the area samples (sums in index order, so the same for any thread
  // count); the vertices and edge midpoints only matter where they exceed the samples' maximum.
  const Vertices area = a.points.topRows(a.num_area_samples);
  const Eigen::VectorXd d2 = b.squared_distances(area);
  s.mean = d2.cwiseSqrt().mean();
  s.rms = std::sqrt(d2.mean());
  s.max = std::sqrt(b.max_squared_distance(a.points, a.num_area_samples, d2.maxCoeff()));
  return s;
}

DistanceStats one_sided_distance(const Vertices& VA, const Faces& FA, const Vertices& VB, const Faces& FB,
                                 const SamplingOptions& options) {
  const DistanceQuery b(VB, FB);
  return one_sided_distance(sample_surface(VA, FA, options), b);
}

SymmetricDistance symmetric_distance(const DistanceStats& a_to_b, const DistanceStats& b_to_a) {
  return {a_to_b, b_to_a, std::max(a_to_b.max, b_to_a.max)};
}

SymmetricDistance symmetric_distance(const Vertices& VA, const Faces& FA, const Vertices& VB, const Faces& FB,
                                     const SamplingOptions& options) {
  // Both directions at once: the tree builds and the sampling are serial, so this keeps both
  // cores busy during them. Each direction's figures do not depend on the schedule.
  DistanceStats a_to_b, b_to_a;
  tbb::parallel_invoke([&] { a_to_b = one_sided_distance(VA, FA, VB, FB, options); },
                       [&] { b_to_a = one_sided_distance(VB, FB, VA, FA, options); });
  return symmetric_distance(a_to_b, b_to_a);
}

double SymmetricDistance::rms() const {
  return std::sqrt(0.5 * (a_to_b.rms * a_to_b.rms + b_to_a.rms * b_to_a.rms));
}

}  // namespace vertexflow
