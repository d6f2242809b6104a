// Mesh connectivity, computed once from the triangles and reused by every later stage.
//
// Manifoldness and what later stages do with non-manifold input
// - An edge is manifold when one (boundary) or two faces share it; a vertex is manifold when
//   its incident faces form a single fan (a disk, or a half-disk on the boundary).
// - Topology is computed for any triangle list, manifold or not, and reports what is wrong
//   (non_manifold_edges, non_manifold_vertices, is_oriented). One-rings are in cyclic order
//   only at manifold vertices.
// - The flow and the curvature estimator (and so the metrics) run on the manifold split of a
//   non-manifold mesh (manifold_split.h); the flow holds the vertices that are not discs. The
//   stages that still need a manifold surface (the unsharp mask, remeshing and simplification)
//   check `is_manifold()` and refuse non-manifold input with std::invalid_argument
//   (describe_non_manifold: the counts and an offending vertex).
#pragma once

#include "vertexflow/mesh.h"

#include <cstdint>
#include <string>
#include <vector>

namespace vertexflow {

/// Undirected edges: #E x 2, each with edges(e, 0) < edges(e, 1).
using Edges = Eigen::Matrix<Index, Eigen::Dynamic, 2, Eigen::RowMajor>;

struct Topology {
  Index num_vertices = 0;
  Index num_faces = 0;

  /// Undirected edges sorted by (smaller vertex, larger vertex).
  Edges edges;
  /// face_edges(f, k) is the edge between corners k and (k + 1) % 3 of face f.
  Faces face_edges;
  /// Number of faces incident to each edge (1 = boundary, 2 = interior, > 2 = non-manifold).
  std::vector<Index> edge_face_count;
  /// face_adjacency(f, k): the face across face_edges(f, k), or -1 on a boundary edge and on
  /// non-manifold edges (more than two faces).
  Faces face_adjacency;

  /// One-ring neighbours of vertex v: ring_vertices[ring_offsets[v] .. ring_offsets[v + 1]).
  /// At a manifold vertex they are in cyclic order, counter-clockwise about the normal of the
  /// first incident face; at a boundary vertex the list starts and ends at the two boundary
  /// neighbours. At a non-manifold vertex they are sorted by index.
  std::vector<Index> ring_offsets;
  std::vector<Index> ring_vertices;
  /// Faces incident to vertex v: vertex_faces[face_offsets[v] .. face_offsets[v + 1]), in the
  /// same cyclic order as the ring at manifold vertices.
  std::vector<Index> face_offsets;
  std::vector<Index> vertex_faces;

  /// Per-vertex flags.
  std::vector<std::uint8_t> is_boundary_vertex;
  std::vector<std::uint8_t> is_manifold_vertex;

  /// Boundary loops as vertex sequences, each running against the direction of its faces'
  /// edges (a single counter-clockwise triangle 0, 1, 2 has the loop 0, 2, 1).
  std::vector<std::vector<Index>> boundary_loops;

  /// Connected components (through shared edges or vertices); isolated vertices form their own.
  Index num_components = 0;
  std::vector<Index> vertex_component;
  std::vector<Index> face_component;

  std::vector<Index> non_manifold_edges;     ///< edges with more than two faces
  std::vector<Index> non_manifold_vertices;  ///< vertices whose faces do not form one fan
  /// Whether every interior manifold edge is traversed in opposite directions by its two faces.
  bool is_oriented = true;

  [[nodiscard]] Index num_edges() const { return static_cast<Index>(edges.rows()); }
  [[nodiscard]] bool is_manifold() const { return non_manifold_edges.empty() && non_manifold_vertices.empty(); }
  [[nodiscard]] bool is_closed() const { return boundary_loops.empty() && is_manifold(); }
  /// V - E + F.
  [[nodiscard]] std::int64_t euler_characteristic() const {
    return std::int64_t{num_vertices} - num_edges() + num_faces;
  }
  /// Total genus sum_c g_c, from chi = sum_c (2 - 2 g_c - b_c), for a manifold oriented mesh;
  /// -1 when the mesh is non-manifold or not orientable as given.
  [[nodiscard]] std::int64_t genus() const;
  /// Neighbours of v, as a contiguous range.
  [[nodiscard]] std::pair<const Index*, const Index*> ring(Index v) const {
    return {ring_vertices.data() + ring_offsets[v], ring_vertices.data() + ring_offsets[v + 1]};
  }
  [[nodiscard]] Index valence(Index v) const { return ring_offsets[v + 1] - ring_offsets[v]; }
};

/// "the mesh is not manifold (E non-manifold edges, V non-manifold vertices, e.g. vertex I)",
/// for the errors of the stages that refuse such meshes.
std::string describe_non_manifold(const Topology& topology);

/// Mean length of the edges of `topology` at positions V (0 without edges).
double mean_edge_length(const Vertices& V, const Topology& topology);

/// Builds the connectivity of triangles F over `num_vertices` vertices. Indices must be in
/// [0, num_vertices) and no face may repeat a vertex (read_mesh removes such faces); throws
/// std::invalid_argument otherwise. Linear time; parallel.
Topology build_topology(const Faces& F, Index num_vertices);

}  // namespace vertexflow
