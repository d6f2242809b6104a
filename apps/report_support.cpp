#include "report_support.h"

#include "cli_common.h"
#include "vertexflow/compare.h"
#include "vertexflow/curvature.h"
#include "vertexflow/metrics.h"
#include "vertexflow/quality.h"
#include "vertexflow/topology.h"

#include <cmath>

namespace vertexflow::cli {

ReportCurvatures report_curvatures(const Mesh& input, const Mesh& result, const Topology& topology,
                                   const Topology* result_topology) {
  const CurvatureOptions options = CompareOptions{}.curvature;
  return {principal_curvatures(input.V, input.F, topology, options),
          principal_curvatures(result.V, result.F, result_topology ? *result_topology : topology, options)};
}

nlohmann::json flow_metrics(const Mesh& input, const Mesh& result, const Topology& topology,
                            const ReportCurvatures& curvatures, const Topology* result_topology) {
  // The definitions of docs/metrics.md, through the same function as `vertexflow compare`: rho and
  // the edge-error CV use the input surface's curvature at each vertex's current position.
  ComparePrecomputed precomputed;
  precomputed.result = {result_topology ? result_topology : &topology, &curvatures.result};
  precomputed.input = {&topology, &curvatures.input};
  const MeshComparison c = compare_meshes(result, input, nullptr, CompareOptions{}, precomputed);
  // The flow's own unit (FlowReport::mean_edge_length is the same number).
  const double edge = mean_edge_length(input.V, topology);
  const double unit = edge > 0 ? edge : 1.0;
  const Faces& F = input.F;
  const Eigen::VectorXd moved = (result.V - input.V).rowwise().norm() / unit;
  const double volume_before = signed_volume(input.V, F);
  nlohmann::json report;
  report["vertices"] = input.V.rows();
  report["faces"] = F.rows();
  if (c.flipped_faces) report["flipped_faces"] = *c.flipped_faces;
  report["degenerate_faces"] = c.degenerate_faces_result;
  report["quality_input"] = to_json(c.quality_input);
  report["quality_result"] = to_json(c.quality_result);
  report["displacement_edge_lengths"] = {{"mean", moved.size() ? moved.mean() : 0.0},
                                         {"max", moved.size() ? moved.maxCoeff() : 0.0}};
  // Drift: how far the result's surface strayed from the input's, in mean input edge lengths.
  const DistanceStats& drift = c.result_input.a_to_b;
  report["drift_edge_lengths"] = {{"mean", drift.mean / unit},
                                  {"rms", drift.rms / unit},
                                  {"max", drift.max / unit},
                                  {"hausdorff", c.result_input.hausdorff / unit}};
  report["redistribution_rho"] = {{"input", c.redistribution_rho_input}, {"result", c.redistribution_rho_result}};
  report["edge_error_cv"] = {{"input", c.edge_error_input.coefficient_of_variation},
                             {"result", c.edge_error_result.coefficient_of_variation}};
  report["edge_error_max_over_mean"] = {{"input", c.edge_error_input.max_over_mean},
                                        {"result", c.edge_error_result.max_over_mean}};
  report["abs_mean_curvature_p95"] = {{"input", c.abs_mean_curvature_input.p95},
                                      {"result", c.abs_mean_curvature_result.p95}};
  report["volume_change_percent"] =
      volume_before != 0 ? 100.0 * (signed_volume(result.V, result.F) - volume_before) / std::abs(volume_before) : 0.0;
  return report;
}

HtmlReportOptions html_report_options(const std::filesystem::path& input, const std::filesystem::path& result) {
  HtmlReportOptions options;
  options.input_label = input.filename().string();
  options.result_label = result.filename().string();
  options.title = "vertexflow: " + options.input_label + " and " + options.result_label;
  return options;
}

}  // namespace vertexflow::cli
