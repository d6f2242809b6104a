// Connectivity changes: simplify (simplify.h) and remesh (remesh.h).
#include "convert.h"

#include "vertexflow/remesh.h"
#include "vertexflow/simplify.h"

namespace vertexflow::python {
namespace {

py::tuple py_simplify(const py::handle& V, const py::handle& F, Index faces, double ratio, bool keep_boundary,
                      int threads) {
  const Mesh mesh = to_mesh(V, F);
  SimplifyOptions options;
  options.target_faces = faces;
  options.target_ratio = ratio;
  options.keep_boundary = keep_boundary;
  if (faces < 0) throw py::value_error("faces must be >= 0 (0: use ratio)");
  SimplifyResult r = without_gil(threads, [&] { return simplify(mesh.V, mesh.F, options); });
  return mesh_tuple(std::move(r.mesh));
}

py::tuple py_remesh(const py::handle& V, const py::handle& F, Index target_vertices, double tolerance, int max_attempts,
                    int iterations, int threads) {
  const Mesh mesh = to_mesh(V, F);
  RemeshOptions options;
  options.target_vertices = target_vertices;
  options.tolerance = tolerance;
  options.max_attempts = max_attempts;
  options.isotropic.iterations = iterations;
  RemeshResult r = without_gil(threads, [&] { return remesh_to_vertex_count(mesh.V, mesh.F, options); });
  return mesh_tuple(std::move(r.mesh));
}

}  // namespace

void register_remesh(py::module_& m) {
  m.def("simplify", &py_simplify, py::arg("V"), py::arg("F"), py::kw_only(), py::arg("faces") = 0,
        py::arg("ratio") = SimplifyOptions{}.target_ratio, py::arg("keep_boundary") = true, py::arg("threads") = 0,
        R"doc(QEM simplification to `faces` faces (or ratio * #F when faces is 0) -> (V, F).)doc");
  m.def("remesh", &py_remesh, py::arg("V"), py::arg("F"), py::kw_only(),
        py::arg("target_vertices") = RemeshOptions{}.target_vertices, py::arg("tolerance") = RemeshOptions{}.tolerance,
        py::arg("max_attempts") = RemeshOptions{}.max_attempts,
        py::arg("iterations") = IsotropicRemeshOptions{}.iterations, py::arg("threads") = 0,
        R"doc(Isotropic remeshing (CGAL) to about target_vertices vertices -> (V, F).)doc");
}

}  // namespace vertexflow::python
