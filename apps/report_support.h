// Pieces of the reports: the metrics of a flow result as JSON (what `vertexflow enhance
// --report` writes beside its options and timings, and what `vertexflow report` and the HTML
// report show), and the options of the HTML report.
#pragma once

#include "vertexflow/html_report.h"
#include "vertexflow/mesh.h"

#include <nlohmann/json.hpp>

#include <filesystem>

namespace vertexflow::cli {

/// Metrics (docs/metrics.md) of `result` (positions, the input's faces F) against `input`:
/// counts, flipped and degenerate faces, quality of both, displacement in mean input edge
/// lengths, redistribution rho, edge-error CV and volume change. Throws std::invalid_argument
/// for a non-manifold mesh (curvature.h).
nlohmann::json flow_metrics(const Vertices& input, const Vertices& result, const Faces& F);

/// HTML report options whose title and labels name the two mesh files.
HtmlReportOptions html_report_options(const std::filesystem::path& input, const std::filesystem::path& result);

}  // namespace vertexflow::cli
