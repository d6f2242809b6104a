// Example: read a mesh in any supported format, print its topology, and write it as binary PLY
// with a per-vertex property (the valence).
//
//   build/bin/example_read_and_convert data/spot.obj /tmp/spot.ply
#include <vertexflow/io.h>
#include <vertexflow/topology.h>

#include <cstdio>
#include <exception>

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: %s INPUT OUTPUT\n", argv[0]);
    return 2;
  }
  try {
    vertexflow::ReadReport report;
    vertexflow::Mesh mesh = vertexflow::read_mesh(argv[1], &report);
    for (const auto& warning : report.warnings()) std::fprintf(stderr, "warning: %s\n", warning.c_str());

    const vertexflow::Topology topology = vertexflow::build_topology(mesh.F, mesh.num_vertices());
    std::printf("%d vertices, %d faces, %d edges, genus %lld, %zu boundary loops, %s\n", mesh.num_vertices(),
                mesh.num_faces(), topology.num_edges(), static_cast<long long>(topology.genus()),
                topology.boundary_loops.size(), topology.is_manifold() ? "manifold" : "non-manifold");

    Eigen::VectorXd valence(mesh.num_vertices());
    for (vertexflow::Index v = 0; v < mesh.num_vertices(); ++v) valence[v] = topology.valence(v);
    mesh.set_vertex_property("valence", valence);

    vertexflow::check_output_path(argv[1], argv[2], /*force=*/false);
    vertexflow::write_mesh(argv[2], mesh);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
  return 0;
}
