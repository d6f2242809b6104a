#include "report_support.h"

#include "cli_common.h"
#include "vertexflow/curvature.h"
#include "vertexflow/flow.h"
#include "vertexflow/metrics.h"
#include "vertexflow/quality.h"
#include "vertexflow/topology.h"

#include <cmath>
#include <system_error>

namespace vertexflow::cli {

nlohmann::json flow_metrics(const Vertices& input, const Vertices& result, const Faces& F) {
  const Topology topology = build_topology(F, static_cast<Index>(input.rows()));
  const Curvature surface = principal_curvatures(input, F, topology);
  const Eigen::VectorXd magnitude = surface.absolute_sum();
  const EdgeErrorStats before = edge_error_stats(input, topology, surface);
  const EdgeErrorStats after = edge_error_stats(result, topology, surface);
  // The flow's own unit (FlowReport::mean_edge_length is the same number).
  const double edge = mean_edge_length(input, topology);
  const Eigen::VectorXd moved = (result - input).rowwise().norm() / (edge > 0 ? edge : 1.0);
  const double volume_before = signed_volume(input, F);
  nlohmann::json report;
  report["vertices"] = input.rows();
  report["faces"] = F.rows();
  report["flipped_faces"] = flipped_faces(input, result, F).size();
  report["degenerate_faces"] = degenerate_faces(result, F).size();
  report["quality_input"] = to_json(summarize_quality(triangle_quality(input, F)));
  report["quality_result"] = to_json(summarize_quality(triangle_quality(result, F)));
  report["displacement_edge_lengths"] = {{"mean", moved.size() ? moved.mean() : 0.0},
                                         {"max", moved.size() ? moved.maxCoeff() : 0.0}};
  report["redistribution_rho"] = {{"input", redistribution_rho(magnitude, input, F)},
                                  {"result", redistribution_rho(magnitude, result, F)}};
  report["edge_error_cv"] = {{"input", before.coefficient_of_variation}, {"result", after.coefficient_of_variation}};
  report["volume_change_percent"] =
      volume_before != 0 ? 100.0 * (signed_volume(result, F) - volume_before) / std::abs(volume_before) : 0.0;
  return report;
}

void check_report_output(const std::filesystem::path& output, const std::vector<std::filesystem::path>& inputs,
                         const std::vector<std::filesystem::path>& other_outputs) {
  for (const auto& input : inputs) check_output_path(input, output, /*force=*/false, /*mesh_output=*/false);
  for (const auto& other : other_outputs) {
    if (other.empty()) continue;
    std::error_code ec;
    if (output.lexically_normal() == other.lexically_normal() ||
        (std::filesystem::exists(output, ec) && std::filesystem::equivalent(output, other, ec)))
      throw IoError(output.string() + ": would overwrite another output of the same command (" + other.string() + ")");
  }
}

HtmlReportOptions html_report_options(const std::filesystem::path& input, const std::filesystem::path& result) {
  HtmlReportOptions options;
  options.input_label = input.filename().string();
  options.result_label = result.filename().string();
  options.title = "vertexflow: " + options.input_label + " and " + options.result_label;
  return options;
}

}  // namespace vertexflow::cli
