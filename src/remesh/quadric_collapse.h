// Garland-Heckbert edge collapse on index arrays: simplify.h's SimplifyMethod::Native. Not
// installed; simplify() is the public entry, and its header states the conventions.
#pragma once

#include "vertexflow/mesh.h"

namespace vertexflow::remesh_detail {

struct QuadricCollapseResult {
  Mesh mesh;            ///< surviving vertices in input order, surviving faces in input order
  Index collapses = 0;  ///< edges collapsed (each removes one vertex)
};

/// Collapses edges of the manifold, consistently oriented (V, F) in order of quadric cost until
/// one more collapse could take the face count below `target_faces` (simplify.h's face budget).
/// The optimal placement and its fallback along the edge are those of CGAL's
/// GarlandHeckbert_plane_policies; the quadrics are its face planes weighted by the faces' areas,
/// and at boundary edges the perpendicular plane weighted 100 times the edge's squared length. A collapse is refused
/// where it would change the topology (the link condition; no vertex left with fewer than three faces inside, one on a
/// boundary) or turn a face over or make it degenerate. With keep_boundary, boundary edges are never collapsed and a
/// collapse onto a boundary vertex leaves that vertex where it is. Serial and deterministic. The caller checks the
/// input (manifold, oriented, indices in range).
QuadricCollapseResult quadric_collapse(const Vertices& V, const Faces& F, Index target_faces, bool keep_boundary);

}  // namespace vertexflow::remesh_detail
