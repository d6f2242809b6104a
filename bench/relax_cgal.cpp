// The same-connectivity peer of issue 16's results table: CGAL 5.5's tangential relaxation
// (Polygon_mesh_processing::tangential_relaxation: each vertex moves to the area-weighted
// centroid of its ring, projected onto its tangent plane; boundary vertices stay), run on a
// mesh read and written by vertexflow's I/O so that the output keeps the input's vertex order.
// Prints {"seconds": ..., "iterations": ...} (the relaxation alone).
//
//   build/bin/relax_cgal IN OUT [ITERATIONS=3]
#include "vertexflow/io.h"
#include "vertexflow/timing.h"

#include <CGAL/Polygon_mesh_processing/tangential_relaxation.h>
#include <CGAL/Simple_cartesian.h>
#include <CGAL/Surface_mesh.h>

#include <chrono>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

using namespace vertexflow;

int main(int argc, char** argv) {
  if (argc < 3 || argc > 4) {
    std::fprintf(stderr, "usage: relax_cgal IN OUT [ITERATIONS=3]\n");
    return 2;
  }
  try {
    const unsigned iterations = argc == 4 ? static_cast<unsigned>(std::stoul(argv[3])) : 3u;
    Mesh mesh = read_mesh(argv[1]);
    using Kernel = CGAL::Simple_cartesian<double>;
    using SurfaceMesh = CGAL::Surface_mesh<Kernel::Point_3>;
    SurfaceMesh sm;
    std::vector<SurfaceMesh::Vertex_index> vertex(static_cast<std::size_t>(mesh.num_vertices()));
    for (Index v = 0; v < mesh.num_vertices(); ++v)
      vertex[static_cast<std::size_t>(v)] = sm.add_vertex(Kernel::Point_3(mesh.V(v, 0), mesh.V(v, 1), mesh.V(v, 2)));
    for (Index f = 0; f < mesh.num_faces(); ++f)
      if (sm.add_face(vertex[static_cast<std::size_t>(mesh.F(f, 0))], vertex[static_cast<std::size_t>(mesh.F(f, 1))],
                      vertex[static_cast<std::size_t>(mesh.F(f, 2))]) == SurfaceMesh::null_face())
        throw std::runtime_error(std::string(argv[1]) + ": not a manifold, consistently oriented mesh");
    const auto start = Clock::now();
    CGAL::Polygon_mesh_processing::tangential_relaxation(sm.vertices(), sm,
                                                         CGAL::parameters::number_of_iterations(iterations));
    const double seconds = seconds_since(start);
    for (Index v = 0; v < mesh.num_vertices(); ++v) {
      const Kernel::Point_3& p = sm.point(vertex[static_cast<std::size_t>(v)]);
      mesh.V.row(v) << p.x(), p.y(), p.z();
    }
    write_mesh(argv[2], mesh);
    std::printf("{\"seconds\": %.6f, \"iterations\": %u}\n", seconds, iterations);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "relax_cgal: %s\n", e.what());
    return 1;
  }
  return 0;
}
