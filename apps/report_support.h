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
/// `topology`, or with `result_topology` for the result when given (its faces differ after
/// edge flips). Throws std::invalid_argument for a non-manifold mesh (curvature.h).
ReportCurvatures report_curvatures(const Mesh& input, const Mesh& result, const Topology& topology,
                                   const Topology* result_topology = nullptr);

/// Metrics (docs/metrics.md) of `result` (the input's faces, moved vertices) against `input`,
/// with the faces' `topology` and the meshes' `curvatures` (report_curvatures): counts, flipped
/// and degenerate faces, quality of both, displacement in mean input edge lengths,
/// redistribution rho, edge-error CV and volume change. Throws CompareError (compare.h) for a
/// mesh compare_meshes refuses. With `result_topology` (the result's faces differ after edge
/// flips) the per-face flip count is not applicable and is left out; the caller reports folds
/// another way (edge_flips.h).
nlohmann::json flow_metrics(const Mesh& input, const Mesh& result, const Topology& topology,
                            const ReportCurvatures& curvatures, const Topology* result_topology = nullptr);

/// HTML report options whose title and labels name the two mesh files.
HtmlReportOptions html_report_options(const std::filesystem::path& input, const std::filesystem::path& result);

}  // namespace vertexflow::cli
