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
// - Output: manifold and consistently oriented, without zero-area faces and without edges
//   shorter than 1e-4 of the target length; what it took is in SurfaceRepairs and
//   RemeshCleanup (on inputs with many holes CGAL's collapses can pinch a vertex between two
//   loops or leave a zero-area face).
// - Raw scans (issue 31; docs/remesh.md): connected pieces too small to remesh (bounding box
//   diagonal below small_piece_edges target edges) are removed, or with
//   SmallPieces::keep copied to the output as they are (outside the short-edge bound above);
//   boundary loops shorter than short_loop_edges target edges are kept: never collapsed, some
//   of their vertices held at their input positions; with fill_hole_edges, loops shorter than
//   that are filled instead. None of this changes a mesh without such pieces or loops.
#pragma once

#include "vertexflow/manifold_split.h"
#include "vertexflow/mesh.h"
#include "vertexflow/quality.h"

#include <vector>

namespace vertexflow {

/// What happens to connected pieces of the input too small to remesh.
enum class SmallPieces {
  remove,  ///< left out of the output
  keep,    ///< copied to the output unchanged: not remeshed, their edges and quality the input's
};

/// One CGAL isotropic_remeshing run.
struct IsotropicRemeshOptions {
  /// Rounds of split, collapse, flip, relax and project (CGAL's number_of_iterations).
  int iterations = 10;
  /// Tangential relaxation steps per round (CGAL's number_of_relaxation_steps).
  int relaxation_steps = 1;
  /// Keep boundary edges exactly as in the input instead of resampling them.
  bool protect_boundary = false;
  /// A connected piece whose bounding-box diagonal is below this many target edge lengths is
  /// too small to remesh (>= 0; 0 remeshes every piece). CGAL turns such a piece into one or a
  /// few faces of any shape (docs/remesh.md).
  double small_piece_edges = 2.0;
  SmallPieces small_pieces = SmallPieces::remove;
  /// A boundary loop shorter than this many target edge lengths is kept (>= 0; 0 resamples
  /// every loop): instead of being collapsed to a triangle of short edges or pinched against
  /// a neighbour, about one vertex per target edge (at least 3) stays at its input position.
  double short_loop_edges = 3.0;
  /// A boundary loop shorter than this many target edge lengths is filled before remeshing
  /// (>= 0; 0, the default, fills none). Holes far below an edge keep needles at their rims
  /// whatever is held (docs/remesh.md); filled, they are remeshed over, and the vertices that
  /// land in them lie on the fill (the loop's triangulation), not on the input surface.
  double fill_hole_edges = 0.0;
};

/// What remeshing a raw scan took beyond CGAL's run (all 0 on a clean input).
struct RemeshCleanup {
  Index small_pieces = 0;           ///< input pieces too small to remesh
  Index small_piece_faces = 0;      ///< their input faces
  bool small_pieces_kept = false;   ///< copied unchanged (SmallPieces::keep) rather than removed
  Index short_loops = 0;            ///< input boundary loops shorter than short_loop_edges, kept
  Index held_loop_vertices = 0;     ///< their vertices held at input positions
  Index filled_holes = 0;           ///< input boundary loops shorter than fill_hole_edges, filled
  Index collapsed_short_edges = 0;  ///< result edges below 1e-4 target lengths, collapsed
  Index flipped_cap_edges = 0;      ///< longest edges of zero-area faces, flipped
  Index removed_cap_faces = 0;      ///< zero-area faces on the boundary, removed
  [[nodiscard]] bool any() const {
    return small_pieces + short_loops + filled_holes + collapsed_short_edges + flipped_cap_edges + removed_cap_faces >
           0;
  }
};

/// Quality of a remesh, over all its faces and apart for the faces at the boundary (rim faces:
/// a corner on a boundary loop) and the others (interior faces). Boundary vertices stay on
/// the input's rims, so rim faces can be poor where rims are short or close together.
struct RemeshQuality {
  QualityStats all, interior, rim;
  Index interior_faces = 0;
  Index rim_faces = 0;
  Index components = 0;
  Index boundary_loops = 0;
  Index non_manifold_vertices = 0;
  Index zero_area_faces = 0;  ///< degenerate_faces (mesh.h): 0 for every remesh
  double min_edge_length = 0;
};

/// The quality of (V, F) as RemeshQuality describes it. Throws std::invalid_argument for an
/// index out of range.
RemeshQuality remesh_quality(const Vertices& V, const Faces& F);

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
  RemeshCleanup cleanup;   ///< of the returned result
  RemeshQuality quality;   ///< of the returned result
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

/// remesh_isotropic with the whole report: one attempt, the cleanup and the quality. Throws
/// like remesh_isotropic.
RemeshResult remesh_to_edge_length(const Vertices& V, const Faces& F, double edge_length,
                                   const IsotropicRemeshOptions& options = {});

}  // namespace vertexflow
