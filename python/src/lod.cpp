// Levels of detail fitted to their dense mesh (lod.h): vertexflow.lod.
#include "convert.h"

#include "vertexflow/lod.h"

#include <pybind11/stl.h>

#include <optional>

namespace vertexflow::python {
namespace {

py::list py_lod(const py::handle& V, const py::handle& F, const std::vector<double>& levels,
                const std::optional<std::vector<Index>>& faces, bool edge_flips, bool keep_boundary,
                bool keep_better_of_two, Index samples, const std::string& simplify_method, int threads) {
  const Mesh dense = to_mesh(V, F);
  LodOptions options;
  options.percent = levels;
  if (faces) options.faces = *faces;
  options.edge_flips = edge_flips;
  options.keep_boundary = keep_boundary;
  options.keep_better_of_two = keep_better_of_two;
  options.simplify_method = enum_option("simplify_method", simplify_method, simplify_method_names());
  if (samples < 0) throw py::value_error("samples must be >= 0");
  options.sampling.samples = samples;
  std::vector<LodLevel> result = without_gil(threads, [&] { return lod(dense, options); });
  py::list out;
  for (LodLevel& level : result) {
    const nlohmann::json report = to_json(level.report);
    py::tuple mesh = mesh_tuple(std::move(level.mesh));
    out.append(py::make_tuple(mesh[0], mesh[1], to_python(report)));
  }
  return out;
}

}  // namespace

void register_lod(py::module_& m) {
  m.def("lod", &py_lod, py::arg("V"), py::arg("F"), py::kw_only(), py::arg("levels") = LodOptions{}.percent,
        py::arg("faces") = py::none(), py::arg("edge_flips") = false, py::arg("keep_boundary") = true,
        py::arg("keep_better_of_two") = true, py::arg("samples") = SamplingOptions{}.samples,
        py::arg("simplify_method") = "native", py::arg("threads") = 0,
        R"doc(Levels of detail of the dense mesh (V, F), as `vertexflow lod` makes them (lod.h,
docs/lod.md): for each level, QEM from the level before, then reference mode's fit against (V, F)
(and edge flips with refits when edge_flips), keeping QEM alone where the fit measures a larger
mean distance (unless keep_better_of_two is False). levels: percent of F's faces, strictly
decreasing; faces: face counts instead. samples: area samples per distance measurement.
simplify_method: "native" or "cgal", the QEM of each level (`vertexflow lod --simplify-method`).
Returns a list of (V, F, report), finest first; report holds the level's faces, the two-sided
mean, RMS and Hausdorff distance to (V, F) for QEM alone ("qem") and the fitted level ("fitted"),
which was kept, the minimum quality, flipped faces and seconds, as the CLI's summary does.)doc");
}

}  // namespace vertexflow::python
