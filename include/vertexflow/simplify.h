// Quadric-error simplification (Garland and Heckbert, "Surface simplification using quadric
// error metrics", SIGGRAPH 1997): edges are collapsed in order of the summed squared distance of
// the new vertex to the planes of the original faces around it, until a face budget is met.
// Two implementations (SimplifyMethod), with the same placement and stopping rule: CGAL's
// Surface_mesh_simplification::edge_collapse with GarlandHeckbert_plane_policies (cost and
// optimal placement), and vertexflow's own collapse on index arrays, three times faster at 1M
// vertices (docs/lod.md). Native weights each face's plane by its area (CGAL: every face alike;
// boundary planes: 100 times, and 100 times the squared edge length in Native), which matters
// on meshes with faces of very different sizes. Both refuse collapses that would change the
// topology or turn a face over; they test that differently (CGAL: the dihedral angle between
// the new faces; Native: each face's normal before and after), so their meshes differ in detail.
//
// Conventions
// - Face budget: the result has target or target + 1 faces. A collapse removes two faces (one
//   at a free boundary edge), so an exact count is not always reachable; the collapses stop
//   as soon as one more could go below the target. When every remaining edge is refused
//   (topology, constraints) the result has more faces and SimplifyReport says so.
// - keep_boundary: boundary edges are never collapsed and vertices on the boundary never move
//   (CGAL's Constrained_placement), so every boundary loop keeps all its vertices at their exact
//   input positions. Without it, the quadrics still penalise leaving the boundary's planes
//   (CGAL's discontinuity multiplier, 100), but boundary vertices may merge and move.
// - Output: vertices are the surviving input vertices in their input order (interior ones at
//   their new optimal positions); faces keep their orientation; genus, components and boundary
//   loops are those of the input. Colours and vertex properties are not carried over.
// - Input: any triangle mesh; one that is not manifold or not consistently oriented is
//   simplified through its manifold split (manifold_split.h), as in remesh.h.
// - Output: manifold and consistently oriented, without zero-area faces (SimplifyReport::repairs
//   says what it took).
#pragma once

#include "vertexflow/manifold_split.h"
#include "vertexflow/mesh.h"

#include <map>
#include <string>

namespace vertexflow {

/// Which implementation collapses the edges (see above).
enum class SimplifyMethod {
  Cgal,    ///< CGAL's edge_collapse (the default of `simplify`)
  Native,  ///< vertexflow's collapse on index arrays (the default of `lod`)
};

/// The methods by the names the CLI (`--method`) and Python (`method=`) take: "cgal", "native".
const std::map<std::string, SimplifyMethod>& simplify_method_names();
/// "cgal" or "native".
std::string simplify_method_name(SimplifyMethod method);

struct SimplifyOptions {
  /// Faces wanted in the result. 0 means: use target_ratio.
  Index target_faces = 0;
  /// Faces wanted as a fraction of the input's faces, in (0, 1]; used when target_faces is 0.
  /// The budget is round(target_ratio * #F), at least 1.
  double target_ratio = 0.1;
  /// Keep every boundary loop exactly (see above).
  bool keep_boundary = true;
  SimplifyMethod method = SimplifyMethod::Cgal;
};

struct SimplifyReport {
  Index input_faces = 0;
  Index target_faces = 0;  ///< the budget the collapses aimed at
  Index output_faces = 0;
  Index collapses = 0;          ///< edges collapsed
  bool reached_target = false;  ///< output_faces <= target_faces + 1
  double seconds = 0;           ///< conversion, collapses and conversion back
  SurfaceRepairs repairs;
};

struct SimplifyResult {
  Mesh mesh;
  SimplifyReport report;
};

/// Simplifies (V, F) to the face budget of `options`. A budget at or above #F returns the input
/// unchanged (apart from dropping unreferenced vertices, and the repairs above). Throws
/// std::invalid_argument for an empty mesh, an index out of range, or options out of range.
SimplifyResult simplify(const Vertices& V, const Faces& F, const SimplifyOptions& options = {});

}  // namespace vertexflow
