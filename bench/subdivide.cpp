// The truths of the control-mesh pairs of issue 30 (docs/method-notes.md, "Inputs held"): CGAL's
// Loop (triangle meshes) or Catmull-Clark (any polygons, read as polygons so that quads stay
// quads) subdivision, ITERATIONS times, triangulated and written as OFF with 17 digits.
//
//   build/bin/subdivide IN OUT.off loop|catmull-clark ITERATIONS
#include <CGAL/Polygon_mesh_processing/triangulate_faces.h>
#include <CGAL/Simple_cartesian.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/boost/graph/IO/polygon_mesh_io.h>
#include <CGAL/subdivision_method_3.h>

#include <cstdio>
#include <exception>
#include <string>

int main(int argc, char** argv) {
  if (argc != 5) {
    std::fprintf(stderr, "usage: subdivide IN OUT.off loop|catmull-clark ITERATIONS\n");
    return 2;
  }
  try {
    using Kernel = CGAL::Simple_cartesian<double>;
    using SurfaceMesh = CGAL::Surface_mesh<Kernel::Point_3>;
    SurfaceMesh sm;
    if (!CGAL::IO::read_polygon_mesh(argv[1], sm) || sm.is_empty())
      throw std::runtime_error(std::string(argv[1]) + ": cannot be read as a manifold polygon mesh");
    const std::string method = argv[3];
    const auto iterations = CGAL::parameters::number_of_iterations(std::stoi(argv[4]));
    if (method == "loop") {
      if (!CGAL::is_triangle_mesh(sm)) throw std::runtime_error(std::string(argv[1]) + ": Loop needs triangles");
      CGAL::Subdivision_method_3::Loop_subdivision(sm, iterations);
    } else if (method == "catmull-clark") {
      CGAL::Subdivision_method_3::CatmullClark_subdivision(sm, iterations);
    } else {
      throw std::runtime_error("unknown method " + method);
    }
    CGAL::Polygon_mesh_processing::triangulate_faces(sm);
    if (!CGAL::IO::write_polygon_mesh(argv[2], sm, CGAL::parameters::stream_precision(17)))
      throw std::runtime_error(std::string(argv[2]) + ": cannot be written");
    std::printf("{\"vertices\": %zu, \"faces\": %zu}\n", static_cast<std::size_t>(sm.number_of_vertices()),
                static_cast<std::size_t>(sm.number_of_faces()));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "subdivide: %s\n", e.what());
    return 1;
  }
  return 0;
}
