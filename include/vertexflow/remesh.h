// Uniform isotropic remeshing: a dense mesh resampled into an evenly sampled one with
// near-equilateral triangles, e.g. the paper's "down-sampled mesh" of Fig. 1(b) that the flow
// then enhances. The implementation is CGAL::Polygon_mesh_processing::isotropic_remeshing
// (Botsch and Kobbelt 2004: split long edges, collapse short ones, flip towards valence 6,
// tangential relaxation, projection onto the input surface).
//
// Conventions
// - Edge lengths are in the input's units. Every output vertex lies on the input surface
//   (CGAL projects each new or moved vertex onto the input triangles).
// - Boundaries: by default boundary edges are resampled along the input's boundary polylines
//   with the same target length (split at midpoints, collapsed onto an endpoint, never moved
//   off the polyline), so every output boundary vertex lies on an input boundary edge and
//   every loop is kept. With protect_boundary the boundary edges are left exactly as they
//   are; CGAL warns that the result is then poor where boundary edges are much longer than
//   the target.
// - Topology: collapses that would change it are refused, so genus, components and boundary
//   loops are those of the input.
// - Output: new vertices and faces, consistently oriented like the input. Colours and vertex
//   properties are not carried over.
// - Input: any triangle mesh. One that is not manifold or not consistently oriented is remeshed
//   through its manifold split (manifold_split.h): non-manifold vertices duplicated,
//   non-manifold edges cut into boundaries, faces oriented per component.
// - Output: manifold and consistently oriented, without zero-area faces; what it took is in
//   SurfaceRepairs (on inputs with many holes CGAL's collapses can pinch a vertex between two
//   loops or leave a zero-area face).
#pragma once

#include "vertexflow/manifold_split.h"
#include "vertexflow/mesh.h"

#include <vector>

namespace vertexflow {

/// One CGAL isotropic_remeshing run.
struct IsotropicRemeshOptions {
  /// Rounds of split, collapse, flip, relax and project (CGAL's number_of_iterations).
  int iterations = 10;
  /// Tangential relaxation steps per round (CGAL's number_of_relaxation_steps).
  int relaxation_steps = 1;
  /// Keep boundary edges exactly as in the input instead of resampling them.
  bool protect_boundary = false;
};

/// Remeshes (V, F) with target edge length `edge_length` (> 0, input units): CGAL splits edges
/// longer than 4/3 of it and collapses those shorter than 4/5 of it. `repairs` (if given)
/// receives what was repaired (see above). Throws std::invalid_argument for an empty mesh, an
/// index out of range, or a length that would give more than 50 million vertices (estimated
/// from the area).
Mesh remesh_isotropic(const Vertices& V, const Faces& F, double edge_length, const IsotropicRemeshOptions& options = {},
                      SurfaceRepairs* repairs = nullptr);

/// Target edge length for about `vertices` vertices of near-equilateral triangles covering
/// `area`: a closed mesh has F ~ 2 V faces of area (sqrt 3 / 4) L^2, so
/// L = sqrt(2 area / (sqrt 3 V)).
double edge_length_for_vertex_count(double area, Index vertices);

struct RemeshOptions {
  /// Vertices wanted in the result, in [3, 50 million].
  Index target_vertices = 6000;
  /// A result is accepted when |#V - target| <= tolerance * target.
  double tolerance = 0.05;
  /// Remeshing runs at most (the first included); the one closest to the target is returned
  /// when none lands within the tolerance.
  int max_attempts = 6;
  IsotropicRemeshOptions isotropic;
};

/// A remeshing run of remesh_to_vertex_count.
struct RemeshAttempt {
  double edge_length = 0;
  Index vertices = 0;
  double seconds = 0;
};

struct RemeshReport {
  std::vector<RemeshAttempt> attempts;
  double edge_length = 0;  ///< of the returned result
  bool within_tolerance = false;
  double seconds = 0;      ///< all attempts
  SurfaceRepairs repairs;  ///< of the returned result
};

struct RemeshResult {
  Mesh mesh;
  RemeshReport report;
};

/// Remeshes (V, F) to about options.target_vertices vertices. The first run uses
/// edge_length_for_vertex_count(surface area, target) times 1.077: CGAL leaves edges about 7 %
/// shorter than the target on average (measured on six bundled meshes; remesh.cpp). Since
/// #V ~ c L^-p with p near 2, each further run corrects the length in log-log space: with
/// p = 2, or the secant slope of the latest two runs (clamped to [1, 4]), until runs on both
/// sides of the target are known; then by interpolation between the closest run on each side,
/// kept strictly inside that bracket. It stops when #V is within the tolerance or after
/// max_attempts runs, returning the run closest to the target. On very regular inputs (e.g. a
/// torus grid) #V jumps with L and the tolerance may be out of reach;
/// RemeshReport::within_tolerance says so. Throws std::invalid_argument like
/// remesh_isotropic, or for options out of range.
RemeshResult remesh_to_vertex_count(const Vertices& V, const Faces& F, const RemeshOptions& options = {});

}  // namespace vertexflow
