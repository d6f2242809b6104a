#include "vertexflow/mesh_info.h"

#include <algorithm>
#include <limits>

namespace vertexflow {

MeshInfo describe_mesh(const Mesh& mesh, const Topology& topology) {
  MeshInfo info;
  info.num_vertices = mesh.num_vertices();
  info.num_faces = mesh.num_faces();
  info.num_edges = topology.num_edges();
  info.bounding_box = bounding_box(mesh.V);
  info.diagonal = info.bounding_box.diagonal();
  if (topology.num_edges() > 0) {
    double sum = 0, lo = std::numeric_limits<double>::infinity(), hi = 0;
    for (Index e = 0; e < topology.num_edges(); ++e) {
      const double length = (mesh.V.row(topology.edges(e, 0)) - mesh.V.row(topology.edges(e, 1))).norm();
      sum += length;
      lo = std::min(lo, length);
      hi = std::max(hi, length);
    }
    info.edge_length_mean = sum / topology.num_edges();
    info.edge_length_min = lo;
    info.edge_length_max = hi;
  }
  for (Index f = 0; f < mesh.num_faces(); ++f) info.surface_area += face_area(mesh.V, mesh.F, f);
  info.boundary_loops = static_cast<Index>(topology.boundary_loops.size());
  info.components = topology.num_components;
  info.euler_characteristic = topology.euler_characteristic();
  info.genus = topology.genus();
  info.manifold = topology.is_manifold();
  info.oriented = topology.is_oriented;
  info.closed = topology.is_closed();
  info.non_manifold_edges = static_cast<Index>(topology.non_manifold_edges.size());
  info.non_manifold_vertices = static_cast<Index>(topology.non_manifold_vertices.size());
  info.quality = summarize_quality(triangle_quality(mesh.V, mesh.F));
  return info;
}

}  // namespace vertexflow
