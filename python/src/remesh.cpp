// Connectivity changes: simplify (simplify.h) and remesh (remesh.h).
#include "convert.h"

#include "vertexflow/remesh.h"
#include "vertexflow/remesh_report_json.h"
#include "vertexflow/simplify.h"

#include <string>

namespace vertexflow::python {
namespace {

py::tuple py_simplify(const py::handle& V, const py::handle& F, Index faces, double ratio, bool keep_boundary,
                      const std::string& method, int threads) {
  const Mesh mesh = to_mesh(V, F);
  SimplifyOptions options;
  options.target_faces = faces;
  options.target_ratio = ratio;
  options.keep_boundary = keep_boundary;
  options.method = enum_option("method", method, simplify_method_names());
  if (faces < 0) throw py::value_error("faces must be >= 0 (0: use ratio)");
  SimplifyResult r = without_gil(threads, [&] { return simplify(mesh.V, mesh.F, options); });
  return mesh_tuple(std::move(r.mesh));
}

// ValueError unless `value` is in [0, 1000], the range of the CLI's --small-piece-edges,
// --short-loop-edges and --fill-holes-below, in the CLI's words.
void check_edges_option(const char* name, double value) {
  if (!(value >= 0 && value <= 1000))
    throw py::value_error(std::string(name) + ": " + std::string(py::repr(py::float_(value))) +
                          " is not in the allowed range ([0, 1000])");
}

// The options of `vertexflow remesh` for raw scans (docs/remesh.md), under the CLI flags' names
// in Python style; report=True adds what `remesh --json` prints but the file names.
py::tuple py_remesh(const py::handle& V, const py::handle& F, Index target_vertices, double tolerance, int max_attempts,
                    int iterations, bool protect_boundary, const std::string& small_pieces, double small_piece_edges,
                    double short_loop_edges, double fill_holes_below, bool report, int threads) {
  const Mesh mesh = to_mesh(V, F);
  RemeshOptions options;
  options.target_vertices = target_vertices;
  options.tolerance = tolerance;
  options.max_attempts = max_attempts;
  options.isotropic.iterations = iterations;
  options.isotropic.protect_boundary = protect_boundary;
  options.isotropic.small_pieces = enum_option<SmallPieces>(
      "small_pieces", small_pieces, {{"remove", SmallPieces::remove}, {"keep", SmallPieces::keep}});
  check_edges_option("small_piece_edges", small_piece_edges);
  check_edges_option("short_loop_edges", short_loop_edges);
  check_edges_option("fill_holes_below", fill_holes_below);
  options.isotropic.small_piece_edges = small_piece_edges;
  options.isotropic.short_loop_edges = short_loop_edges;
  options.isotropic.fill_hole_edges = fill_holes_below;
  RemeshResult r = without_gil(threads, [&] { return remesh_to_vertex_count(mesh.V, mesh.F, options); });
  if (!report) return mesh_tuple(std::move(r.mesh));
  py::object summary = to_python(remesh_report_json(r, mesh.num_vertices(), options, /*searched=*/true));
  const py::tuple arrays = mesh_tuple(std::move(r.mesh));
  return py::make_tuple(arrays[0], arrays[1], summary);
}

}  // namespace

void register_remesh(py::module_& m) {
  m.def("simplify", &py_simplify, py::arg("V"), py::arg("F"), py::kw_only(), py::arg("faces") = 0,
        py::arg("ratio") = SimplifyOptions{}.target_ratio, py::arg("keep_boundary") = true, py::arg("method") = "cgal",
        py::arg("threads") = 0,
        R"doc(QEM simplification to `faces` faces (or ratio * #F when faces is 0) -> (V, F). method:
"cgal" (CGAL's edge collapse) or "native" (vertexflow's own: area-weighted quadrics, several times
faster), as `vertexflow simplify --method`.)doc");
  const IsotropicRemeshOptions isotropic;
  m.def("remesh", &py_remesh, py::arg("V"), py::arg("F"), py::kw_only(),
        py::arg("target_vertices") = RemeshOptions{}.target_vertices, py::arg("tolerance") = RemeshOptions{}.tolerance,
        py::arg("max_attempts") = RemeshOptions{}.max_attempts, py::arg("iterations") = isotropic.iterations,
        py::arg("protect_boundary") = isotropic.protect_boundary, py::arg("small_pieces") = "remove",
        py::arg("small_piece_edges") = isotropic.small_piece_edges,
        py::arg("short_loop_edges") = isotropic.short_loop_edges,
        py::arg("fill_holes_below") = isotropic.fill_hole_edges, py::arg("report") = false, py::arg("threads") = 0,
        R"doc(Isotropic remeshing (CGAL) to about target_vertices vertices -> (V, F), or (V, F, report)
with report=True. The keywords are `vertexflow remesh`'s flags (docs/remesh.md):

protect_boundary: keep boundary edges exactly as in the input (default: resample them along
    the boundary).
small_pieces: "remove" or "keep" the connected pieces too small to remesh (keep: copied to the
    output unchanged).
small_piece_edges: a piece whose bounding-box diagonal is below this many target edges is too
    small to remesh (0: remesh every piece), in [0, 1000].
short_loop_edges: a boundary loop shorter than this many target edges is kept, not collapsed
    (0: resample every loop), in [0, 1000].
fill_holes_below: fill boundary loops shorter than this many target edges before remeshing (0:
    fill none), in [0, 1000].
report: also return the dict `vertexflow remesh --json` prints, without "input" and "output":
    vertices, faces, runs, quality, quality_interior, quality_rim (2r/R statistics over all,
    interior and rim faces), interior_faces, rim_faces, components, boundary_loops, cleanup
    (small_pieces, small_piece_faces, short_loops_kept, ...), repairs and the options.)doc");
}

}  // namespace vertexflow::python
