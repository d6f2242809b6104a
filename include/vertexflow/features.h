// Sharp features of a triangle mesh: creases and corners, as the flow respects them
// (FlowOptions::feature_angle, flow.h). Angles in degrees; the normals compared are the faces'
// own (face_normal, mesh.h), so the result does not depend on the mesh's scale, position or
// vertex order.
#pragma once

#include "vertexflow/mesh.h"
#include "vertexflow/topology.h"

#include <array>
#include <vector>

namespace vertexflow {

/// Sharp features of a mesh: an interior edge is sharp when the normals of its two faces differ
/// by more than the feature angle and it separates two patches, the face sets connected across
/// non-sharp edges (a chain of such edges that ends inside one patch is an under-sampled ridge
/// or scan noise, not a crease).
struct SurfaceFeatures {
  enum class Kind : char { Smooth, Crease, Corner };
  std::vector<char> sharp_edge;  ///< per edge of the topology
  /// The sharp edges at vertex v, in increasing order: sharp_at[sharp_start[v]] up to
  /// sharp_at[sharp_start[v + 1]] (one array rather than a vector per vertex: 20 bytes per
  /// vertex fewer through the flow).
  std::vector<Index> sharp_start, sharp_at;
  std::vector<Index> face_patch;  ///< per face
  /// Crease: exactly two sharp edges that continue each other within the feature angle;
  /// Corner: one, three or more, or two that turn.
  std::vector<Kind> vertex_kind;
  /// Vertices on an edge sharper than the feature angle, a crease or not: their normal
  /// averages across the edge, so the Phong lift takes no height from them.
  std::vector<char> on_sharp_edge;
  Vertices vertex_normals;  ///< of the mesh (curvature.h), for the Phong height of projections

  /// The number of sharp edges at v.
  [[nodiscard]] Index sharp_count(Index v) const {
    return sharp_start[static_cast<std::size_t>(v) + 1] - sharp_start[static_cast<std::size_t>(v)];
  }
  /// Calls visit(e) for each sharp edge e at v, in increasing order.
  template <class Visit>
  void for_each_sharp_edge(Index v, Visit&& visit) const {
    for (Index k = sharp_start[static_cast<std::size_t>(v)]; k < sharp_start[static_cast<std::size_t>(v) + 1]; ++k)
      visit(sharp_at[static_cast<std::size_t>(k)]);
  }
};

/// Features for `angle_degrees` (>= 180 marks nothing sharp by angle). The interior edges in
/// `crease_edges` (vertex pairs, either order; pairs that are no interior edge are ignored) are
/// sharp whatever their angle and are never dropped as short chains or as ending in one patch:
/// texture seams and material boundaries (VertexConstraints::crease_edges, guard.h).
SurfaceFeatures detect_features(const Vertices& V, const Faces& F, const Topology& topology, double angle_degrees,
                                const std::vector<std::array<Index, 2>>& crease_edges = {});

}  // namespace vertexflow
