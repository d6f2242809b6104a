// A manifold, consistently oriented copy of any triangle mesh, for the stages that need one
// (the flow; later curvature and the metrics), and the way back to the input's vertices.
//
// Real files are often not manifold: vertex-clustered scans share vertices and edges between
// sheets, CAD exports have bowties and fins, games flip a face here and there. Instead of
// refusing them, such a mesh is cut where its neighbourhoods are not discs, and the parts that
// are discs are processed as usual:
// - Faces are oriented per component by a breadth-first walk over manifold edges (like CGAL's
//   polygon-soup orientation): a face whose traversal of a shared edge agrees with its
//   neighbour's is reversed, and where no choice of orientations is consistent (a Moebius strip)
//   the edge is cut instead. Each component keeps the orientation most of its faces had.
// - Edges shared by more than two faces, and edges left with a conflict, are cut: they become
//   boundary edges of the copy.
// - Every vertex is split into one copy per fan: the faces around it that are connected across
//   uncut edges (CGAL's duplicate_non_manifold_vertices does the same for polygon meshes).
// A vertex with more than one copy cannot move without tearing the surface: it is `held`.
#pragma once

#include "vertexflow/mesh.h"
#include "vertexflow/topology.h"

#include <vector>

namespace vertexflow {

/// What split_non_manifold changed, for the reports of the stages that use it.
struct ManifoldSplitCounts {
  Index held_vertices = 0;   ///< input vertices split into more than one copy
  Index reversed_faces = 0;  ///< faces reversed to agree with their component
  Index cut_edges = 0;       ///< non-manifold edges and orientation conflicts cut
  [[nodiscard]] bool any() const { return held_vertices + reversed_faces + cut_edges > 0; }
};

/// What the CGAL-based stages (remesh.h, simplify.h) repaired: the input they converted
/// through its manifold split, and what they removed or duplicated in their output so that it
/// is manifold, consistently oriented and has no zero-area face.
struct SurfaceRepairs {
  ManifoldSplitCounts input_split;
  Index removed_degenerate_faces = 0;  ///< zero-area faces left by the collapses, removed
  Index duplicated_vertices = 0;       ///< vertices pinched between fans, duplicated
};

struct ManifoldSplit {
  /// The copy's vertices: input vertex source_vertex[s] for copy s, at the same position.
  Vertices V;
  /// The input's faces in the same order, each corner re-indexed to the copy of its vertex in
  /// that face's fan, and corners 1 and 2 swapped where `reversed_face`.
  Faces F;
  /// Per copy: the input vertex it copies. Copies of one vertex are consecutive; vertices come
  /// in input order; an isolated input vertex has one copy.
  std::vector<Index> source_vertex;
  /// Per input vertex: its first copy (first_copy[v] .. first_copy[v + 1] are its copies).
  std::vector<Index> first_copy;
  /// Per input vertex: 1 where it has more than one copy (a non-manifold vertex, an end of a
  /// non-manifold edge, or a vertex cut apart by an orientation conflict).
  std::vector<char> held;
  /// Per face: 1 where its corners were reversed to agree with its component.
  std::vector<char> reversed_face;
  Index held_vertices = 0;           ///< input vertices with more than one copy
  Index reversed_faces = 0;          ///< faces whose orientation was reversed
  Index cut_non_manifold_edges = 0;  ///< edges of more than two faces, cut
  Index cut_orientation_edges = 0;   ///< manifold edges cut because no orientation agrees across them

  /// Whether the input was already manifold and consistently oriented (then V, F equal the input).
  [[nodiscard]] bool unchanged() const {
    return held_vertices == 0 && reversed_faces == 0 && cut_non_manifold_edges == 0 && cut_orientation_edges == 0;
  }
  [[nodiscard]] ManifoldSplitCounts counts() const {
    return {held_vertices, reversed_faces, cut_non_manifold_edges + cut_orientation_edges};
  }
};

/// The manifold, consistently oriented copy of (V, F), whose topology is `topology`
/// (build_topology(F, V.rows())). The copy's topology is manifold and oriented. Deterministic;
/// linear time. Throws std::invalid_argument if `topology` was built for another mesh.
ManifoldSplit split_non_manifold(const Vertices& V, const Faces& F, const Topology& topology);

}  // namespace vertexflow
