// Internal to the flow stage: moving points back onto the input surface, respecting its sharp
// features.
#pragma once

#include "vertexflow/features.h"
#include "vertexflow/mesh.h"
#include "vertexflow/topology.h"

#include <vector>

namespace vertexflow {

/// Moves each row i listed in `rows` of `points` (a query point near vertex i of (V, F)) to a
/// point of the surface (V, F) near it, found by a walk that starts at vertex i: a smooth
/// vertex walks over the faces of its own patch, from face to a closer face sharing a vertex,
/// until none is closer, and is then lifted to the Phong surface; a crease vertex walks likewise
/// along its crease's sharp edges; a corner is not moved. A walk, not a global nearest-point
/// query, so that a point never jumps through a thin wall, and bounded by the features, so that
/// no vertex leaves its crease or crosses one (which would cut the edge off a CAD part).
/// Parallel over rows, deterministic.
void project_near_vertices(Vertices& points, const std::vector<Index>& rows, const Vertices& V, const Faces& F,
                           const Topology& topology, const SurfaceFeatures& features);

}  // namespace vertexflow
