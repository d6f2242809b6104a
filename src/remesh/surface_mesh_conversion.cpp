#include "surface_mesh_conversion.h"

#include "vertexflow/topology.h"

#include <CGAL/Polygon_mesh_processing/manifoldness.h>
#include <CGAL/Polygon_mesh_processing/repair_degeneracies.h>

#include <stdexcept>
#include <vector>

namespace vertexflow::remesh_detail {

namespace PMP = CGAL::Polygon_mesh_processing;

namespace {

SurfaceMesh manifold_to_surface_mesh(const Vertices& V, const Faces& F, const Topology& topology,
                                     const std::string& stage) {
  SurfaceMesh mesh;
  mesh.reserve(static_cast<SurfaceMesh::size_type>(V.rows()), static_cast<SurfaceMesh::size_type>(topology.num_edges()),
               static_cast<SurfaceMesh::size_type>(F.rows()));
  for (Index v = 0; v < V.rows(); ++v) mesh.add_vertex(Kernel::Point_3(V(v, 0), V(v, 1), V(v, 2)));
  for (Index f = 0; f < F.rows(); ++f) {
    const auto face = mesh.add_face(SurfaceMesh::Vertex_index(static_cast<SurfaceMesh::size_type>(F(f, 0))),
                                    SurfaceMesh::Vertex_index(static_cast<SurfaceMesh::size_type>(F(f, 1))),
                                    SurfaceMesh::Vertex_index(static_cast<SurfaceMesh::size_type>(F(f, 2))));
    // Cannot happen for a manifold, oriented F; kept so that a gap in that is an error, not a hole.
    if (face == SurfaceMesh::null_face())
      throw std::invalid_argument(stage + ": face " + std::to_string(f) + " cannot be added to a halfedge mesh");
  }
  return mesh;
}

}  // namespace

SurfaceMesh to_surface_mesh(const Vertices& V, const Faces& F, const std::string& stage, ManifoldSplitCounts* split) {
  if (V.rows() == 0 || F.rows() == 0) throw std::invalid_argument(stage + ": the mesh is empty");
  // build_topology also checks the indices and repeated vertices.
  const Topology topology = build_topology(F, static_cast<Index>(V.rows()));
  if (topology.is_manifold() && topology.is_oriented) {
    if (split) *split = {};
    return manifold_to_surface_mesh(V, F, topology, stage);
  }
  const ManifoldSplit copy = split_non_manifold(V, F, topology);
  if (split) *split = copy.counts();
  return manifold_to_surface_mesh(copy.V, copy.F, build_topology(copy.F, static_cast<Index>(copy.V.rows())), stage);
}

Mesh from_surface_mesh(SurfaceMesh& mesh, SurfaceRepairs* repairs) {
  // CGAL's collapses can leave zero-area faces and vertices pinched between two boundary
  // loops where holes are close (a remesh of a scan with holes: 128 and 72 of them), which
  // the flow and the metrics refuse. Removing degenerate faces can itself pinch a vertex, so
  // it comes first.
  const auto faces_before = mesh.number_of_faces();
  PMP::remove_degenerate_faces(mesh);
  const auto duplicated = PMP::duplicate_non_manifold_vertices(mesh);
  if (repairs) {
    repairs->removed_degenerate_faces = static_cast<Index>(faces_before - mesh.number_of_faces());
    repairs->duplicated_vertices = static_cast<Index>(duplicated);
  }
  // Surface_mesh iterators skip removed elements; vertex indices are renumbered densely.
  std::vector<Index> new_index(mesh.num_vertices(), -1);
  Index count = 0;
  for (const auto v : mesh.vertices())
    if (!mesh.is_isolated(v)) new_index[v.idx()] = count++;
  Mesh out;
  out.V.resize(count, 3);
  for (const auto v : mesh.vertices()) {
    const Index i = new_index[v.idx()];
    if (i < 0) continue;
    const auto& p = mesh.point(v);
    out.V.row(i) << p.x(), p.y(), p.z();
  }
  out.F.resize(static_cast<Index>(mesh.number_of_faces()), 3);
  Index f = 0;
  for (const auto face : mesh.faces()) {
    int k = 0;
    for (const auto v : CGAL::vertices_around_face(mesh.halfedge(face), mesh)) {
      if (k == 3) throw std::logic_error("from_surface_mesh: a face is not a triangle");
      out.F(f, k++) = new_index[v.idx()];
    }
    if (k != 3) throw std::logic_error("from_surface_mesh: a face is not a triangle");
    ++f;
  }
  return out;
}

}  // namespace vertexflow::remesh_detail
