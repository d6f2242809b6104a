// Internal to the flow stage: moving points back onto the input surface, respecting its sharp
// features.
#pragma once

#include "vertexflow/mesh.h"
#include "vertexflow/topology.h"

#include <vector>

namespace vertexflow {

/// Sharp features of a mesh: an interior edge is sharp when the normals of its two faces differ
/// by more than the feature angle and it separates two patches, the face sets connected across
/// non-sharp edges (a chain of such edges that ends inside one patch is an under-sampled ridge
/// or scan noise, not a crease).
struct SurfaceFeatures {
  enum class Kind : char { Smooth, Crease, Corner };
  std::vector<char> sharp_edge;                  ///< per edge of the topology
  std::vector<std::vector<Index>> vertex_sharp;  ///< sharp edges at each vertex
  std::vector<Index> face_patch;                 ///< per face
  /// Crease: exactly two sharp edges that continue each other within the feature angle;
  /// Corner: one, three or more, or two that turn.
  std::vector<Kind> vertex_kind;
  /// Vertices on an edge sharper than the feature angle, a crease or not: their normal
  /// averages across the edge, so the Phong lift takes no height from them.
  std::vector<char> on_sharp_edge;
  Vertices vertex_normals;  ///< of the mesh (curvature.h), for the Phong height of projections
};

/// Features for `angle_degrees` (>= 180 marks nothing sharp).
SurfaceFeatures detect_features(const Vertices& V, const Faces& F, const Topology& topology, double angle_degrees);

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
