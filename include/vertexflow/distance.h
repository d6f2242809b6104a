// Distances between triangle meshes (docs/metrics.md, "Shape fidelity").
//
// Distance A -> B: points on A (area-uniform samples, plus every vertex and every edge
// midpoint of A, thinned evenly to a fixed count on large meshes), each measured to the exact
// closest point on B's triangles. The closest points come from a bounding-box hierarchy over B
// (ours, built on all threads: src/metrics/face_box_tree.h says why) with CGAL's exact
// point-triangle projection, in double precision. Where several faces of B are equally close
// the answer names the lowest-numbered one, so every answer is the smallest (squared distance,
// face) over B's faces: it does not depend on the tree, on where a search starts or on the order
// of the queries.
//
// Conventions
// - Lengths are in the units of the meshes' coordinates; callers that want them relative to a
//   bounding-box diagonal or a mean edge length divide by it (compare.h does).
// - Mean and RMS are taken over the area-uniform samples only, so they estimate the surface
//   integrals (1/|A|) int_A d and sqrt((1/|A|) int_A d^2) independently of how A is
//   tessellated. The maximum is taken over all points: vertices and edge midpoints are where
//   a coarse mesh strays furthest from a fine one, and random samples would miss them. Without
//   area samples (samples = 0, or every face of A degenerate) mean and RMS are over all points.
//   On a mesh with more vertices and edges than SamplingOptions::max_vertices_and_midpoints
//   the maximum is over an even subset of them: an estimate from below, at a fixed cost.
// - Memory: a tree takes about 26 bytes per face of B (a 64-byte node per two to three faces and
//   one 4-byte face index per face; triangles are read from V and F when visited), plus the copy
//   of V and F unless it borrows them (DistanceQuery::Borrow).
// - Determinism: for a given seed the samples are the same on every run and for any number of
//   threads (they are drawn in one sequential stream), and the parallel queries run in fixed
//   blocks with sums taken in a fixed order, so every figure is bit-identical for 1 or more
//   threads.
// - Any triangle list is accepted (non-manifold, open, with degenerate faces): a degenerate
//   triangle of B is treated as its longest edge.
#pragma once

#include "vertexflow/mesh.h"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <vector>

namespace vertexflow {

struct SamplingOptions {
  /// Area-uniform random samples (i.i.d., each face chosen with probability proportional to
  /// its area, then a uniform point in it). metrics.md asks for at least 200,000.
  Index samples = 200000;
  /// Seed of the random stream (std::mt19937_64); equal seeds give equal samples.
  std::uint64_t seed = 1;
  /// Also take every vertex of A (rows of V, referenced or not).
  bool vertices = true;
  /// Also take the midpoint of every edge of A (each undirected edge once).
  bool edge_midpoints = true;
  /// At most this many vertices and edge midpoints together: above it, an even subset of each
  /// (in proportion to their counts) is taken, so that the points, their memory and the
  /// queries stay bounded on large meshes (at 1M vertices there are 4.3M of them). 500,000
  /// keeps every point of meshes up to about 125k vertices (each of data/ unchanged) and costs
  /// about 2.5 times the 200,000 area samples' queries. Negative: no limit.
  Index max_vertices_and_midpoints = 500000;
};

/// Points on a mesh, in three consecutive blocks: the area-uniform samples, then the vertices,
/// then the edge midpoints (those taken, see SamplingOptions::max_vertices_and_midpoints).
struct SurfaceSamples {
  Vertices points;
  Index num_area_samples = 0;
  Index num_vertices = 0;
  Index num_edge_midpoints = 0;
};

/// Samples the surface (V, F) as described by `options`. Area samples are sorted along a Morton
/// curve, so that neighbouring queries are close in space whatever the order of the faces (a
/// Loop-subdivided mesh's are scattered: 5M samples of one sorted by face took 4.6 s to query
/// against its 500k-vertex simplification, sorted along the curve 3.5 s); vertices are in index
/// order and edge midpoints in the order of their (lower, higher) vertex pairs, or when thinned
/// an even subset of each in that order, then sorted along a Morton curve (for the queries'
/// first guesses). Throws std::invalid_argument if `options.samples` is negative or F indexes
/// outside V.
SurfaceSamples sample_surface(const Vertices& V, const Faces& F, const SamplingOptions& options = {});

/// The closest point of a mesh B to a query point.
struct ClosestPoint {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();  ///< on B
  double squared_distance = 0;                      ///< |query - point|^2
  Index face = -1;                                  ///< the face of B containing `point`
  /// Barycentric coordinates of `point` in `face` (weights of its corners F(face, 0..2)):
  /// non-negative, summing to 1. Use them to interpolate B's per-vertex data at `point`.
  Eigen::Vector3d barycentric = Eigen::Vector3d::Zero();
};

/// Diagnostic (the tests' hook): how many DistanceQuery trees this process has built over meshes
/// of exactly `num_faces` faces. A command that measures against a dense reference builds one
/// tree of it (reference_surface.h).
std::uint64_t distance_trees_built(Index num_faces);

/// Closest-point queries against a fixed mesh B: a box tree built once, then queried any
/// number of times, from any number of threads. Holds its own copy of B's vertices and faces,
/// or borrows the caller's.
class DistanceQuery {
 public:
  /// Builds the tree over the triangles of (V, F). Throws std::invalid_argument if F is empty
  /// or indexes outside V.
  DistanceQuery(const Vertices& V, const Faces& F);
  /// Tag of the constructor that borrows the mesh.
  struct Borrow {};
  /// The same tree without a copy of V and F (24 bytes per vertex and 12 per face less): they
  /// are the caller's and must outlive the query unchanged. The answers are the same.
  DistanceQuery(const Vertices& V, const Faces& F, Borrow);
  DistanceQuery(Vertices&& V, const Faces& F, Borrow) = delete;
  DistanceQuery(const Vertices& V, Faces&& F, Borrow) = delete;
  DistanceQuery(Vertices&& V, Faces&& F, Borrow) = delete;
  ~DistanceQuery();
  DistanceQuery(DistanceQuery&&) noexcept;
  DistanceQuery& operator=(DistanceQuery&&) noexcept;
  DistanceQuery(const DistanceQuery&) = delete;
  DistanceQuery& operator=(const DistanceQuery&) = delete;

  /// The closest point of B to p. Where several faces of B are equally close (p on the medial
  /// axis, or the closest point on an edge shared by two faces) the lowest-numbered one's.
  [[nodiscard]] ClosestPoint closest_point(const Eigen::Vector3d& p) const;

  /// closest_point for every row of P, in parallel (TBB); the same result for any number of
  /// threads.
  [[nodiscard]] std::vector<ClosestPoint> closest_points(const Vertices& P) const;

  /// The same with a guess per point: near_faces[i] is a face of B near row i's answer (its
  /// answer in an earlier query of a nearby point, say), or -1 for none. The search starts from
  /// that face, which prunes more of the tree when the guess is good; the answers are the same.
  /// Throws
  /// std::invalid_argument unless near_faces is empty (no guesses) or has one entry per row of P,
  /// each below B's face count.
  [[nodiscard]] std::vector<ClosestPoint> closest_points(const Vertices& P, std::span<const Index> near_faces) const;

  /// The same answers as closest_points(P, near_faces), handed to `visit(i, answer)` for each row
  /// i of P instead of returned: once per row, from several threads at once (TBB) and in no fixed
  /// order, so `visit` must be safe to call concurrently for different rows (writing row i's own
  /// slot of an array is). What a caller that turns the answers into something else at once
  /// needs: no array of #P answers (64 bytes each) is made, filled and read back. Throws as
  /// closest_points does.
  void for_each_closest_point(const Vertices& P, std::span<const Index> near_faces,
                              const std::function<void(Index, const ClosestPoint&)>& visit) const;

  /// Squared distance from every row of P to B (#P), in parallel, thread-count independent.
  [[nodiscard]] Eigen::VectorXd squared_distances(const Vertices& P) const;

  /// The largest squared distance from the rows first_row, first_row + 1, ... of P to B, or
  /// `at_least` when none is larger. Exact, and faster than squared_distances when `at_least`
  /// is near the answer: a point whose distance to a point of B found cheaply (on the triangle
  /// nearest to the previous point) is already within sqrt(at_least) is not searched for.
  [[nodiscard]] double max_squared_distance(const Vertices& P, Index first_row = 0, double at_least = 0) const;

  /// B's vertices and faces (the copy the tree was built from, or the borrowed ones).
  [[nodiscard]] const Vertices& vertices() const;
  [[nodiscard]] const Faces& faces() const;

  /// The bytes this query holds: its tree's nodes and face order (about 26 per face), and its
  /// copy of B's V and F unless they are borrowed. Borrowed V and F are not counted.
  [[nodiscard]] std::size_t memory_bytes() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// One-sided distance A -> B (lengths in the meshes' units).
struct DistanceStats {
  double mean = 0;   ///< mean over the area-uniform samples
  double rms = 0;    ///< root mean square over the area-uniform samples
  double max = 0;    ///< maximum over all points (samples, vertices, edge midpoints)
  Index points = 0;  ///< points measured in total

  /// The same figures divided by `length` (e.g. a bounding-box diagonal); `points` unchanged.
  [[nodiscard]] DistanceStats relative_to(double length) const {
    return {mean / length, rms / length, max / length, points};
  }
};

/// Distance from the points `a` (sampled on A by sample_surface) to the mesh B behind `b`.
DistanceStats one_sided_distance(const SurfaceSamples& a, const DistanceQuery& b);

/// Distance from mesh A to mesh B: samples A with `options` and queries a tree built over B.
DistanceStats one_sided_distance(const Vertices& VA, const Faces& FA, const Vertices& VB, const Faces& FB,
                                 const SamplingOptions& options = {});

/// Both one-sided distances and the Hausdorff distance max(max A->B, max B->A).
struct SymmetricDistance {
  DistanceStats a_to_b;
  DistanceStats b_to_a;
  double hausdorff = 0;

  [[nodiscard]] SymmetricDistance relative_to(double length) const {
    return {a_to_b.relative_to(length), b_to_a.relative_to(length), hausdorff / length};
  }
  /// Two-sided figures: the mean of the two one-sided means, and the RMS over both directions
  /// (sqrt of the mean of the two mean squares).
  [[nodiscard]] double mean() const { return 0.5 * (a_to_b.mean + b_to_a.mean); }
  [[nodiscard]] double rms() const;
};

/// A -> B and B -> A with the same sampling options for both.
SymmetricDistance symmetric_distance(const Vertices& VA, const Faces& FA, const Vertices& VB, const Faces& FB,
                                     const SamplingOptions& options = {});

/// Combines the two one-sided figures (hausdorff = the larger maximum).
SymmetricDistance symmetric_distance(const DistanceStats& a_to_b, const DistanceStats& b_to_a);

}  // namespace vertexflow
