// Measurement: principal_curvatures (curvature.h) and compare (compare.h).
#include "convert.h"

#include "vertexflow/compare.h"
#include "vertexflow/curvature.h"

namespace vertexflow::python {
namespace {

py::object py_principal_curvatures(const py::handle& V, const py::handle& F, int smoothing_rounds, int threads) {
  const Mesh mesh = to_mesh(V, F);
  CurvatureOptions options;
  if (smoothing_rounds < 0) throw py::value_error("smoothing_rounds must be >= 0");
  options.smoothing_rounds = smoothing_rounds;
  Curvature c = without_gil(threads, [&] { return principal_curvatures(mesh.V, mesh.F, options); });
  // Leaked on purpose: a static py::object would be released after the interpreter is gone.
  static const py::handle type =
      py::object(py::module_::import("vertexflow._core").attr("PrincipalCurvatures")).release();
  return type(to_numpy(std::move(c.k1)), to_numpy(std::move(c.k2)), to_numpy(std::move(c.T1)),
              to_numpy(std::move(c.T2)), to_numpy(std::move(c.N)));
}

nlohmann::json distance_json(const SymmetricDistance& d) {
  const auto one = [](const DistanceStats& s) {
    return nlohmann::json{{"mean", s.mean}, {"rms", s.rms}, {"max", s.max}, {"points", s.points}};
  };
  return {{"mean", d.mean()},
          {"rms", d.rms()},
          {"hausdorff", d.hausdorff},
          {"a_to_b", one(d.a_to_b)},
          {"b_to_a", one(d.b_to_a)}};
}

py::dict py_compare(const py::handle& V_result, const py::handle& F_result, const py::handle& V_input,
                    const py::handle& F_input, const py::object& reference, int threads) {
  const Mesh result = to_mesh(V_result, F_result, "V_result", "F_result");
  const Mesh input = to_mesh(V_input, F_input, "V_input", "F_input");
  Mesh ref;
  const bool has_reference = !reference.is_none();
  if (has_reference) {
    const py::sequence pair = reference.cast<py::sequence>();
    if (pair.size() != 2) throw py::value_error("reference must be a pair (V, F)");
    ref = to_mesh(pair[0], pair[1], "reference V", "reference F");
  }
  const MeshComparison c =
      without_gil(threads, [&] { return compare_meshes(result, input, has_reference ? &ref : nullptr); });
  nlohmann::json j;
  const auto edge = [](const EdgeErrorStats& s) {
    return nlohmann::json{
        {"mean", s.mean}, {"max_over_mean", s.max_over_mean}, {"coefficient_of_variation", s.coefficient_of_variation}};
  };
  const auto quality = [](const QualityStats& q) {
    return nlohmann::json{{"min", q.min}, {"mean", q.mean}, {"p5", q.p5}, {"fraction_below_0_3", q.fraction_below_0_3}};
  };
  const auto percentiles = [](const MeanCurvaturePercentiles& h) {
    return nlohmann::json{{"p5", h.p5}, {"p50", h.p50}, {"p95", h.p95}, {"p99", h.p99}};
  };
  j["length_scale"] = c.length_scale;
  j["has_reference"] = c.has_reference;
  j["distance"]["result_input"] = distance_json(c.result_input);
  j["distance"]["result_reference"] = c.result_reference ? distance_json(*c.result_reference) : nlohmann::json(nullptr);
  j["distance"]["input_reference"] = c.input_reference ? distance_json(*c.input_reference) : nlohmann::json(nullptr);
  j["edge_error"] = {{"input", edge(c.edge_error_input)}, {"result", edge(c.edge_error_result)}};
  j["redistribution_rho"] = {{"input", c.redistribution_rho_input}, {"result", c.redistribution_rho_result}};
  j["abs_mean_curvature"] = {{"input", percentiles(c.abs_mean_curvature_input)},
                             {"result", percentiles(c.abs_mean_curvature_result)}};
  j["quality"] = {{"input", quality(c.quality_input)}, {"result", quality(c.quality_result)}};
  j["degenerate_faces"] = {{"input", c.degenerate_faces_input}, {"result", c.degenerate_faces_result}};
  j["same_connectivity"] = c.same_connectivity;
  j["flipped_faces"] = c.flipped_faces ? nlohmann::json(*c.flipped_faces) : nlohmann::json(nullptr);
  return to_python(j);
}

}  // namespace

void register_metrics(py::module_& m) {
  m.attr("PrincipalCurvatures") =
      py::module_::import("collections")
          .attr("namedtuple")("PrincipalCurvatures", py::make_tuple("k1", "k2", "T1", "T2", "N"));
  m.attr("PrincipalCurvatures").attr("__module__") = "vertexflow";
  m.def("principal_curvatures", &py_principal_curvatures, py::arg("V"), py::arg("F"), py::kw_only(),
        py::arg("smoothing_rounds") = 0, py::arg("threads") = 0,
        R"doc(Principal curvatures (Rusinkiewicz 2004) of every vertex: PrincipalCurvatures(k1, k2, T1, T2, N),
k1 >= k2 (n,) arrays, T1, T2, N unit (n, 3) arrays. Convex with outward normals is positive.)doc");
  m.def("compare", &py_compare, py::arg("V_result"), py::arg("F_result"), py::arg("V_input"), py::arg("F_input"),
        py::kw_only(), py::arg("reference") = py::none(), py::arg("threads") = 0,
        R"doc(Every figure of docs/metrics.md for a result against its input (and a dense reference=(V, F)):
distances, edge-error CV, redistribution rho, |H| percentiles, quality, degenerate and flipped faces.)doc");
}

}  // namespace vertexflow::python
