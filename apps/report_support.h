// Pieces of the reports: the metrics of a flow result as JSON (what `vertexflow enhance
// --report` writes beside its options and timings, and what `vertexflow report` and the HTML
// report show), and checks and options for report files.
#pragma once

#include "vertexflow/html_report.h"
#include "vertexflow/mesh.h"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <vector>

namespace vertexflow::cli {

/// Metrics (../docs/metrics.md) of `result` (positions, the input's faces F) against `input`:
/// counts, flipped and degenerate faces, quality of both, displacement in mean input edge
/// lengths, redistribution rho, edge-error CV and volume change. Throws std::invalid_argument
/// for a non-manifold mesh (curvature.h).
nlohmann::json flow_metrics(const Vertices& input, const Vertices& result, const Faces& F);

/// Throws IoError unless the report file `output` may be written: not a directory, none of
/// `inputs` (even with --force: a report never replaces a mesh), and none of the other outputs
/// of the same command (empty paths are skipped).
void check_report_output(const std::filesystem::path& output, const std::vector<std::filesystem::path>& inputs,
                         const std::vector<std::filesystem::path>& other_outputs);

/// HTML report options whose title and labels name the two mesh files.
HtmlReportOptions html_report_options(const std::filesystem::path& input, const std::filesystem::path& result);

}  // namespace vertexflow::cli
