// Internal to the enhance engine: what moved vertices do to a mesh's attributes
// (docs/attributes.md). Charts are the face sets connected across edges that are no chart
// boundary: a texture seam (the two faces give an endpoint different rows of a TexCoord corner
// channel) or a label boundary (the faces differ in a Label face channel other than OBJ's
// smoothing groups, say their material).
#pragma once

#include "vertexflow/mesh.h"
#include "vertexflow/topology.h"

#include <array>
#include <vector>

namespace vertexflow::attributes_detail {

/// Chart boundaries among the faces `faces` of `input` (rows of input.F; `topology` is built
/// over exactly those rows, in that order, and input.V's vertex count).
struct ChartBoundaries {
  std::vector<char> on_edge;                ///< per edge of `topology`
  std::vector<std::array<Index, 2>> edges;  ///< the same edges as vertex pairs
};
ChartBoundaries chart_boundaries(const Mesh& input, const std::vector<Index>& faces, const Topology& topology);

struct TransportReport {
  Index vertices_moved = 0;
  /// (vertex, chart) pairs located on the input surface.
  Index wedges_located = 0;
  /// Largest distance from a moved vertex to where it was located, relative to the input's
  /// mean edge length: about 0 for the flow (its vertices stay on the surface, Phong-lifted),
  /// the distance the fit moved off it for the fit and smooth mode.
  double max_location_distance = 0;
  /// Corner-table rows added because a row was shared by vertices that moved apart.
  Index rows_added = 0;
  /// Normal channels recomputed from the moved geometry.
  int normal_channels = 0;
};

/// The attributes of `input` for its vertices moved to `moved` (same vertex count) and the face
/// list `output_F` (input.F with the rows of `faces` possibly changed by edge flips, which never
/// flip a chart boundary). Each moved vertex is located on the input surface, in each of its
/// charts, by a walk from its own faces that never crosses a chart boundary; interpolable
/// channels are re-sampled there by barycentric interpolation (Color rounded to its type,
/// Weights renormalised), labels kept, Normal channels recomputed from the moved faces with the
/// input's split (corners sharing a row are averaged together) and orientation kept. Vertices
/// that did not move keep their values exactly.
MeshAttributes transport_attributes(const Mesh& input, const std::vector<Index>& faces, const Topology& topology,
                                    const ChartBoundaries& charts, const Vertices& moved, const Faces& output_F,
                                    TransportReport& report);

}  // namespace vertexflow::attributes_detail
