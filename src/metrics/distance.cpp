// Mesh-to-mesh distances (include/vertexflow/distance.h): our face box tree
// (metrics/face_box_tree.h) for the search, CGAL's point-triangle projection for the closest
// points, TBB for the parallel queries.
#include "vertexflow/distance.h"

#include "common/bucket_by_key.h"
#include "metrics/face_box_tree.h"
#include "numerics/vertex_ordering.h"

#include <CGAL/Simple_cartesian.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/parallel_sort.h>
#include <tbb/partitioner.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <mutex>
#include <numeric>
#include <random>
#include <span>
#include <stdexcept>
#include <string>

namespace vertexflow {
namespace {

// Constructions (the closest point) are in doubles either way; Simple_cartesian skips the
// interval filtering of the exact-predicates kernels, which buys nothing here.
using Kernel = CGAL::Simple_cartesian<double>;
using Triangle = Kernel::Triangle_3;

// The mesh a tree is over (not owned).
struct MeshFaces {
  const Vertices* V = nullptr;
  const Faces* F = nullptr;
  [[nodiscard]] Kernel::Point_3 corner(Index f, int k) const {
    const auto p = V->row((*F)(f, k));
    return {p[0], p[1], p[2]};
  }
  [[nodiscard]] Triangle triangle(Index f) const { return {corner(f, 0), corner(f, 1), corner(f, 2)}; }
};

// A closest point and its face (-1: none yet).
struct Answer {
  Kernel::Point_3 point{0, 0, 0};
  Index face = -1;
};

// Squared distance from p to an axis-aligned box (0 inside).
inline double squared_distance_to_box(const Kernel::Point_3& p, const CGAL::Bbox_3& box) {
  const double dx = std::max(0.0, std::max(box.xmin() - p.x(), p.x() - box.xmax()));
  const double dy = std::max(0.0, std::max(box.ymin() - p.y(), p.y() - box.ymax()));
  const double dz = std::max(0.0, std::max(box.zmin() - p.z(), p.z() - box.zmax()));
  return dx * dx + dy * dy + dz * dz;
}

// Queries run in blocks of this many points. A block's first query searches the whole tree,
// each later one starts from the triangle of the previous answer (consecutive points are close:
// samples are sorted along a Morton curve, edges by vertex). The answers do not depend on the
// start (equally close faces go to the lowest-numbered), so the blocks only keep the work the
// same for any schedule.
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

// Sorts the rows [first, first + count) of P along a Morton curve in P's bounding box (ties by
// row, so the order is fixed). For a thinned subset of vertices or midpoints: in index order
// consecutive points are far apart, so each query's first guess (the previous answer's
// triangle) is poor; in this order the maximum's queries took 0.82 s of CPU instead of 2.09 s
// (500,000 points of the 1M-vertex armadillo).
void sort_along_morton_curve(Vertices& P, std::int64_t first, std::int64_t count) {
  if (count < 2) return;
  auto rows = P.middleRows(first, count);
  const Eigen::RowVector3d low = rows.colwise().minCoeff(), high = rows.colwise().maxCoeff();
  const Eigen::RowVector3d scale = (high - low).cwiseMax(1e-300).cwiseInverse() * 2097151.0;
  std::vector<std::pair<std::uint64_t, std::int64_t>> key(static_cast<std::size_t>(count));
  tbb::parallel_for(tbb::blocked_range<std::int64_t>(0, count, 4096), [&](const tbb::blocked_range<std::int64_t>& r) {
    for (std::int64_t i = r.begin(); i != r.end(); ++i) {
      const Eigen::RowVector3d t = (rows.row(i) - low).cwiseProduct(scale);
      key[static_cast<std::size_t>(i)] = {morton_code_of_cells(t.x(), t.y(), t.z()), i};
    }
  });
  // The keys are unique (each carries its row), so the order is the same for any thread count.
  tbb::parallel_sort(key.begin(), key.end());
  const Vertices copy = rows;
  tbb::parallel_for(tbb::blocked_range<std::int64_t>(0, count, 4096), [&](const tbb::blocked_range<std::int64_t>& r) {
    for (std::int64_t i = r.begin(); i != r.end(); ++i) rows.row(i) = copy.row(key[static_cast<std::size_t>(i)].second);
  });
}

// Each undirected edge of F once, as (smaller vertex) << 32 | (larger vertex), in increasing
// order. The sides are bucketed by their smaller vertex and each bucket sorted on its own: the
// order of one sort of all 3 #F keys at a fraction of its cost (at 10M vertices the sort was
// most of a sampling's 6 s).
std::vector<std::uint64_t> sorted_edges(const Faces& F, Index nv) {
  const Index nf = static_cast<Index>(F.rows());
  KeyBuckets<Index, std::int64_t> buckets =
      bucket_by_key<Index, std::int64_t>(static_cast<std::size_t>(nv), [&](auto&& emit) {
        for (Index f = 0; f < nf; ++f)
          for (int k = 0; k < 3; ++k) {
            const Index i = F(f, k), j = F(f, (k + 1) % 3);
            if (i != j) emit(static_cast<std::size_t>(std::min(i, j)), std::max(i, j));
          }
      });
  const std::vector<std::int64_t>& start = buckets.start;
  std::vector<Index>& larger = buckets.items;
  // Each bucket sorted and made unique in place; its distinct count, then their offsets.
  std::vector<std::int64_t> distinct(static_cast<std::size_t>(nv) + 1, 0);
  tbb::parallel_for(tbb::blocked_range<Index>(0, nv, 4096), [&](const tbb::blocked_range<Index>& r) {
    for (Index v = r.begin(); v != r.end(); ++v) {
      const auto first = larger.begin() + start[static_cast<std::size_t>(v)];
      const auto last = larger.begin() + start[static_cast<std::size_t>(v) + 1];
      std::sort(first, last);
      distinct[static_cast<std::size_t>(v) + 1] = std::unique(first, last) - first;
    }
  });
  for (std::size_t v = 0; v < static_cast<std::size_t>(nv); ++v) distinct[v + 1] += distinct[v];
  std::vector<std::uint64_t> edges(static_cast<std::size_t>(distinct.back()));
  tbb::parallel_for(tbb::blocked_range<Index>(0, nv, 4096), [&](const tbb::blocked_range<Index>& r) {
    for (Index v = r.begin(); v != r.end(); ++v) {
      const std::int64_t from = start[static_cast<std::size_t>(v)];
      const std::int64_t to = distinct[static_cast<std::size_t>(v)];
      const std::int64_t count = distinct[static_cast<std::size_t>(v) + 1] - to;
      for (std::int64_t k = 0; k < count; ++k)
        edges[static_cast<std::size_t>(to + k)] =
            std::uint64_t{static_cast<std::uint32_t>(v)} << 32 |
            static_cast<std::uint32_t>(larger[static_cast<std::size_t>(from + k)]);
    }
  });
  return edges;
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
  // (The areas in parallel, their sum in face order: the same bits as one loop.)
  std::vector<double> cumulative(static_cast<std::size_t>(nf));
  tbb::parallel_for(tbb::blocked_range<Index>(0, nf, 4096), [&](const tbb::blocked_range<Index>& r) {
    for (Index f = r.begin(); f != r.end(); ++f) cumulative[static_cast<std::size_t>(f)] = face_area(V, F, f);
  });
  double total = 0;
  for (double& c : cumulative) c = total += c;

  SurfaceSamples s;
  s.num_area_samples = total > 0 ? options.samples : 0;
  // Each undirected edge once: sort the keys (smaller vertex, larger vertex) of all face sides.
  // (build_topology has the edges too, but refuses non-manifold and repeated-vertex faces,
  // which distances must accept.)
  std::vector<std::uint64_t> edges;
  if (options.edge_midpoints) edges = sorted_edges(F, static_cast<Index>(V.rows()));
  // Thinning (SamplingOptions::max_vertices_and_midpoints): an even subset of each block, the
  // blocks in proportion to their sizes; take(k, n, j) is the j-th of k evenly spaced of n.
  const std::int64_t all_vertices = options.vertices ? V.rows() : 0;
  const auto all_midpoints = static_cast<std::int64_t>(edges.size());
  std::int64_t vertices_taken = all_vertices, midpoints_taken = all_midpoints;
  const std::int64_t cap = options.max_vertices_and_midpoints;
  if (cap >= 0 && all_vertices + all_midpoints > cap) {
    vertices_taken = all_vertices * cap / (all_vertices + all_midpoints);
    midpoints_taken = cap - vertices_taken;
  }
  const auto take = [](std::int64_t k, std::int64_t n, std::int64_t j) { return k == n ? j : j * n / k; };
  s.num_vertices = static_cast<Index>(vertices_taken);
  s.num_edge_midpoints = static_cast<Index>(midpoints_taken);
  s.points.resize(std::int64_t{s.num_area_samples} + s.num_vertices + s.num_edge_midpoints, 3);

  if (s.num_area_samples > 0) {
    // One sequential stream, so the samples do not depend on the thread count. Doubles in
    // [0, 1) from the top 53 bits: mt19937_64's output is fully specified by the standard,
    // std::uniform_real_distribution's is not.
    std::mt19937_64 random(options.seed);
    const auto uniform = [&random] { return static_cast<double>(random() >> 11) * 0x1.0p-53; };
    const auto n = static_cast<std::size_t>(s.num_area_samples);
    // The stream is drawn in one pass (three numbers a sample, in the order of the samples);
    // the faces' binary searches, which miss the cache on a large mesh, run in parallel, and so
    // does the placing of the points.
    std::vector<double> u(n), r1(n), r2(n);
    for (std::size_t i = 0; i < n; ++i) {
      u[i] = uniform() * total;
      r1[i] = uniform();
      r2[i] = uniform();
    }
    std::vector<Index> face(n);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 4096), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t i = r.begin(); i != r.end(); ++i) {
        const auto it = std::upper_bound(cumulative.begin(), cumulative.end(), u[i]);
        // u < total = cumulative.back() unless rounding made them equal: take the last face of
        // non-zero area then.
        auto f = static_cast<Index>(it - cumulative.begin());
        if (f == nf)
          f = static_cast<Index>(std::lower_bound(cumulative.begin(), cumulative.end(), total) - cumulative.begin());
        face[i] = f;
      }
    });
    std::vector<double>().swap(u);
    // Counting sort by face (stable, so the order within a face is the order of drawing): each
    // sample's row, then the points in parallel.
    std::vector<Index> offset(static_cast<std::size_t>(nf) + 1, 0);
    for (std::size_t i = 0; i < n; ++i) ++offset[static_cast<std::size_t>(face[i]) + 1];
    for (Index f = 0; f < nf; ++f) offset[static_cast<std::size_t>(f) + 1] += offset[static_cast<std::size_t>(f)];
    std::vector<Index> row(n);
    for (std::size_t i = 0; i < n; ++i) row[i] = offset[static_cast<std::size_t>(face[i])]++;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 4096), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t i = r.begin(); i != r.end(); ++i) {
        const Index f = face[i];
        double a = r1[i], b = r2[i];
        if (a + b > 1) {  // reflect the far half of the unit square onto the triangle: uniform
          a = 1 - a;
          b = 1 - b;
        }
        const Eigen::RowVector3d p0 = V.row(F(f, 0));
        s.points.row(row[i]) = p0 + a * (V.row(F(f, 1)) - p0) + b * (V.row(F(f, 2)) - p0);
      }
    });
  }
  for (std::int64_t k = 0; k < vertices_taken; ++k)
    s.points.row(s.num_area_samples + k) = V.row(take(vertices_taken, all_vertices, k));
  const std::int64_t first_midpoint = std::int64_t{s.num_area_samples} + s.num_vertices;
  for (std::int64_t k = 0; k < midpoints_taken; ++k) {
    const std::uint64_t e = edges[static_cast<std::size_t>(take(midpoints_taken, all_midpoints, k))];
    const auto i = static_cast<Index>(e >> 32), j = static_cast<Index>(e & 0xffffffffu);
    s.points.row(first_midpoint + k) = 0.5 * (V.row(i) + V.row(j));
  }
  sort_along_morton_curve(s.points, 0, s.num_area_samples);
  if (vertices_taken < all_vertices) sort_along_morton_curve(s.points, s.num_area_samples, vertices_taken);
  if (midpoints_taken < all_midpoints) sort_along_morton_curve(s.points, first_midpoint, midpoints_taken);
  return s;
}

// ---------------------------------------------------------------------------------------------
// Closest points

struct DistanceQuery::Impl {
  Vertices own_V;  // the copy, unless borrowed
  Faces own_F;
  MeshFaces mesh;  // own_V and own_F, or the caller's
  FaceBoxTree tree;

  // The closest point of B to q, starting from `hint` (a point of its face, or no face). Of
  // equally close faces the lowest-numbered one, so the answer is the smallest (squared
  // distance, face) over all faces, whatever the tree, the hint or the thread: the tree visits
  // every box within the best distance so far, including those exactly at it.
  Answer closest(const Kernel::Point_3& q, const Answer& hint) const {
    Answer best = hint;
    double best_d2 = hint.face >= 0 ? CGAL::squared_distance(q, hint.point) : std::numeric_limits<double>::infinity();
    const double at[3] = {q.x(), q.y(), q.z()};
    tree.search(at, best_d2, [&](Index f) {
      const Triangle t = mesh.triangle(f);
      // A face whose own box is further than the best point cannot hold a nearer one.
      if (squared_distance_to_box(q, t.bbox()) > best_d2 * FaceBoxTree::kRoundingSlack) return;
      const Kernel::Point_3 closest = Kernel().construct_projected_point_3_object()(t, q);
      const double d2 = CGAL::squared_distance(q, closest);
      // The first face visited is taken whatever its distance, so that a query whose distances
      // are all NaN or infinite (a non-finite point or mesh) still names a face.
      if (best.face < 0 || d2 < best_d2 || (d2 == best_d2 && f < best.face)) {
        best = {closest, f};
        best_d2 = d2;
      }
    });
    return best;
  }

  // Counts the tree (distance_trees_built) and builds it over (V, F), which must outlive it.
  void build_tree(const Vertices& V, const Faces& F);

  // Runs fn(point index, query point, answer) for the rows [first, last) of P, in fixed blocks
  // (see kQueryBlock). With skip_at_most >= 0, a point whose first guess is already within that
  // squared distance is skipped (its distance cannot exceed it): for maxima. `near_faces`, when
  // given, names a face of B near each point's answer (or -1): the search starts from that face
  // instead of the previous point's.
  template <class Fn>
  void for_each_closest(const Vertices& P, std::size_t first, std::size_t last, double skip_at_most, Fn&& fn,
                        const Index* near_faces = nullptr) const {
    const std::size_t blocks = (last - first + kQueryBlock - 1) / kQueryBlock;
    const auto project = [this](Index face, const Kernel::Point_3& q) {
      return Answer{Kernel().construct_projected_point_3_object()(mesh.triangle(face), q), face};
    };
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, blocks, 1),
        [&](const tbb::blocked_range<std::size_t>& range) {
          for (std::size_t block = range.begin(); block != range.end(); ++block) {
            const std::size_t begin = first + block * kQueryBlock, end = std::min(last, begin + kQueryBlock);
            Answer hint;
            for (std::size_t i = begin; i < end; ++i) {
              const Kernel::Point_3 q = to_cgal(P.row(static_cast<Eigen::Index>(i)).transpose());
              if (near_faces && near_faces[i] >= 0) {
                hint = project(near_faces[i], q);
              } else if (hint.face >= 0) {
                // Start from the closest point of the previous answer's triangle: a tighter
                // first bound than the previous closest point itself.
                hint = project(hint.face, q);
              }
              if (skip_at_most >= 0 && hint.face >= 0 && CGAL::squared_distance(q, hint.point) <= skip_at_most)
                continue;
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

  ClosestPoint make_answer(const Kernel::Point_3& q, const Answer& answer) const {
    ClosestPoint c;
    c.point = to_eigen(answer.point);
    c.squared_distance = CGAL::squared_distance(q, answer.point);
    c.face = answer.face;
    const Vertices& V = *mesh.V;
    const Faces& F = *mesh.F;
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
  check_indices(V, F, "DistanceQuery");
  impl_->own_V = V;
  impl_->own_F = F;
  impl_->build_tree(impl_->own_V, impl_->own_F);
}

DistanceQuery::DistanceQuery(const Vertices& V, const Faces& F, Borrow) : impl_(std::make_unique<Impl>()) {
  if (F.rows() == 0) throw std::invalid_argument("DistanceQuery: the mesh has no faces");
  check_indices(V, F, "DistanceQuery");
  impl_->build_tree(V, F);
}

void DistanceQuery::Impl::build_tree(const Vertices& V, const Faces& F) {
  {
    const std::lock_guard lock(trees_mutex);
    ++trees_by_size()[static_cast<Index>(F.rows())];
  }
  mesh = {&V, &F};
  tree = FaceBoxTree(V, F);
}

DistanceQuery::~DistanceQuery() = default;
DistanceQuery::DistanceQuery(DistanceQuery&&) noexcept = default;
DistanceQuery& DistanceQuery::operator=(DistanceQuery&&) noexcept = default;

std::size_t DistanceQuery::memory_bytes() const {
  return sizeof(Impl) + impl_->tree.memory_bytes() + static_cast<std::size_t>(impl_->own_V.size()) * sizeof(double) +
         static_cast<std::size_t>(impl_->own_F.size()) * sizeof(Index);
}

const Vertices& DistanceQuery::vertices() const {
  return *impl_->mesh.V;
}
const Faces& DistanceQuery::faces() const {
  return *impl_->mesh.F;
}

ClosestPoint DistanceQuery::closest_point(const Eigen::Vector3d& p) const {
  const Kernel::Point_3 q = to_cgal(p);
  return impl_->make_answer(q, impl_->closest(q, Answer{}));
}

std::vector<ClosestPoint> DistanceQuery::closest_points(const Vertices& P) const {
  return closest_points(P, {});
}

namespace {

void check_near_faces(const Vertices& P, std::span<const Index> near_faces, Index faces) {
  if (!near_faces.empty() && near_faces.size() != static_cast<std::size_t>(P.rows()))
    throw std::invalid_argument("closest_points: near_faces must have one face per point");
  for (const Index f : near_faces)
    if (f >= faces) throw std::invalid_argument("closest_points: a near face is out of range");
}

}  // namespace

std::vector<ClosestPoint> DistanceQuery::closest_points(const Vertices& P, std::span<const Index> near_faces) const {
  check_near_faces(P, near_faces, static_cast<Index>(impl_->mesh.F->rows()));
  std::vector<ClosestPoint> out(static_cast<std::size_t>(P.rows()));
  impl_->for_each_closest(
      P, 0, static_cast<std::size_t>(P.rows()), -1.0,
      [&](std::size_t i, const Kernel::Point_3& q, const Answer& a) { out[i] = impl_->make_answer(q, a); },
      near_faces.empty() ? nullptr : near_faces.data());
  return out;
}

void DistanceQuery::for_each_closest_point(const Vertices& P, std::span<const Index> near_faces,
                                           const std::function<void(Index, const ClosestPoint&)>& visit) const {
  check_near_faces(P, near_faces, static_cast<Index>(impl_->mesh.F->rows()));
  impl_->for_each_closest(
      P, 0, static_cast<std::size_t>(P.rows()), -1.0,
      [&](std::size_t i, const Kernel::Point_3& q, const Answer& a) {
        visit(static_cast<Index>(i), impl_->make_answer(q, a));
      },
      near_faces.empty() ? nullptr : near_faces.data());
}

Eigen::VectorXd DistanceQuery::squared_distances(const Vertices& P) const {
  Eigen::VectorXd out(P.rows());
  impl_->for_each_closest(P, [&](std::size_t i, const Kernel::Point_3& q, const Answer& a) {
    out[static_cast<Eigen::Index>(i)] = CGAL::squared_distance(q, a.point);
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
                          [&](std::size_t i, const Kernel::Point_3& q, const Answer& a) {
                            double& slot = block_max[(i - first) / kQueryBlock];
                            slot = std::max(slot, CGAL::squared_distance(q, a.point));
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
  const DistanceQuery b(VB, FB, DistanceQuery::Borrow{});
  return one_sided_distance(sample_surface(VA, FA, options), b);
}

SymmetricDistance symmetric_distance(const DistanceStats& a_to_b, const DistanceStats& b_to_a) {
  return {a_to_b, b_to_a, std::max(a_to_b.max, b_to_a.max)};
}

SymmetricDistance symmetric_distance(const Vertices& VA, const Faces& FA, const Vertices& VB, const Faces& FB,
                                     const SamplingOptions& options) {
  // Small meshes: both directions at once, as their sampling is partly serial and their tree
  // builds split into few tasks. Large ones (200,000 faces or more): one after the other, so that
  // one tree is alive at a time (each build and sampling has work enough for every thread). Each
  // direction's figures do not depend on the schedule.
  constexpr Index kOneTreeAtATimeFrom = 200000;
  DistanceStats a_to_b, b_to_a;
  const auto a_to_b_task = [&] { a_to_b = one_sided_distance(VA, FA, VB, FB, options); };
  const auto b_to_a_task = [&] { b_to_a = one_sided_distance(VB, FB, VA, FA, options); };
  if (FA.rows() < kOneTreeAtATimeFrom && FB.rows() < kOneTreeAtATimeFrom) {
    tbb::parallel_invoke(a_to_b_task, b_to_a_task);
  } else {
    a_to_b_task();
    b_to_a_task();
  }
  return symmetric_distance(a_to_b, b_to_a);
}

double SymmetricDistance::rms() const {
  return std::sqrt(0.5 * (a_to_b.rms * a_to_b.rms + b_to_a.rms * b_to_a.rms));
}

}  // namespace vertexflow
