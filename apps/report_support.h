// Pieces of the reports: the metrics of a flow result as JSON (what `vertexflow enhance
// --report` writes beside its options and timings, and what `vertexflow report` and the HTML
// report show), and the options of the HTML report.
#pragma once

#include "vertexflow/curvature.h"
#include "vertexflow/html_report.h"
#include "vertexflow/mesh.h"
#include "vertexflow/topology.h"

#include <nlohmann/json.hpp>

#include <filesystem>

namespace vertexflow::cli {

/// Each mesh's own curvature (principal_curvatures at the mesh's own scale, with the estimator
/// options compare_meshes and the HTML report use by default), computed once per command for
/// both: flow_metrics measures with it and write_html_report colours with its mean curvature.
struct ReportCurvatures {
  Curvature input;
  Curvature result;
};

/// The curvatures of `input` and `result` (a flow result: the input's faces), with the faces'
/// `topology`. Throws std::invalid_argument for a non-manifold mesh (curvature.h).
ReportCurvatures report_curvatures(const Mesh& input, const Mesh& result, const Topology& topology);

/// Metrics (docs/metrics.md) of `result` (the input's faces, moved vertices) against `input`,
/// with the faces' `topology` and the meshes' `curvatures` (report_curvatures): counts, flipped
/// and degenerate faces, quality of both, displacement in mean input edge lengths,
/// redistribution rho, edge-error CV and volume change. Throws CompareError (compare.h) for a
/// mesh compare_meshes refuses.
nlohmann::json flow_metrics(const Mesh& input, const Mesh& result, const Topology& topology,
                            const ReportCurvatures& curvatures);

/// HTML report options whose title and labels name the two mesh files.
HtmlReportOptions html_report_options(const std::filesystem::path& input, const std::filesystem::path& result);

}  // namespace vertexflow::cli
