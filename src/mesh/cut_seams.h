// Internal to the enhance engine: seams that a file stores cut open. Formats and exporters that
// hold one texture coordinate (or normal, or colour) per vertex, such as PLY, glTF and most game
// pipelines, split a vertex into copies at the same position wherever its attributes jump. The
// mesh is then open along every seam. Flowing each side on its own would open cracks, so the
// engine welds such copies for the methods and holds the seam as a crease (enhance.h).
#pragma once

#include "vertexflow/mesh.h"
#include "vertexflow/topology.h"

#include <array>
#include <vector>

namespace vertexflow {

struct CutSeams {
  /// Per vertex: the lowest-indexed vertex it is welded to; itself when it is not welded.
  std::vector<Index> representative;
  /// The welded seam edges, as pairs of representatives (smaller first), in the order of their
  /// first boundary half-edge in the faces.
  std::vector<std::array<Index, 2>> edges;
  /// Vertices that are not their own representative.
  Index vertices_welded = 0;
  [[nodiscard]] bool empty() const { return vertices_welded == 0; }
};

/// The cut-open seams of the triangles F over V (`topology` = build_topology(F, V.rows())). Two
/// boundary edges are one seam when they join the same two positions (bitwise equal
/// coordinates, -0 equal to +0) in opposite directions, and no other boundary edge joins those
/// positions. The endpoints of seam edges are welded, unless the welded vertex would not be a
/// single fan (two pieces that touch at a point stay apart). `representative` is empty when the
/// mesh has no boundary.
CutSeams find_cut_seams(const Vertices& V, const Faces& F, const Topology& topology);

}  // namespace vertexflow
