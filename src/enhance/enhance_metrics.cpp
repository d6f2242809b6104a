// enhance_metrics (enhance.h): the figures of docs/metrics.md for an enhance result, as the
// reports of `enhance --report`, `batch` and the Python module write them.
#include "enhance/workable_faces.h"
#include "vertexflow/compare.h"
#include "vertexflow/curvature.h"
#include "vertexflow/edge_flips.h"
#include "vertexflow/enhance.h"
#include "vertexflow/metrics.h"
#include "vertexflow/progress.h"
#include "vertexflow/quality.h"
#include "vertexflow/report_json.h"
#include "vertexflow/topology.h"

#include <cmath>
#include <optional>

namespace vertexflow {
namespace {

// Two-sided, as issue 16 measures: the mean of both one-sided means, the RMS over both
// directions, and the Hausdorff distance, in the meshes' units. The reference's tree and samples
// (the large side) come from the ReferenceSurface, built once for both meshes; the mesh's own
// tree borrows its V and F and lives for its one query.
nlohmann::json distance_to(const Mesh& m, const ReferenceSurface& reference) {
  const DistanceStats to_reference = one_sided_distance(sample_surface(m.V, m.F), reference.distance_query());
  const SymmetricDistance d = symmetric_distance(
      to_reference, one_sided_distance(reference.samples(), DistanceQuery(m.V, m.F, DistanceQuery::Borrow{})));
  return {{"mean", d.mean()},
          {"rms", d.rms()},
          {"hausdorff", d.hausdorff},
          {"to_reference", distance_stats_json(d.a_to_b, 1.0)},
          {"from_reference", distance_stats_json(d.b_to_a, 1.0)}};
}

}  // namespace

nlohmann::json enhance_metrics(const Mesh& input, const Mesh& result, const ReferenceSurface* reference,
                               EnhanceCurvatures* curvatures_out, const EnhanceMetricsReuse* reuse) {
  // What the run kept for this input: its topology, over all of its faces, all of them workable.
  const EnhanceMetricsReuse::Kept* kept = reuse ? reuse->kept() : nullptr;
  if (kept && (kept->topology.num_vertices != input.num_vertices() || kept->topology.num_faces != input.num_faces() ||
               kept->faces != enhance_detail::faces_fingerprint(input.F)))
    kept = nullptr;
  // The faces enhance() held out (zero area, a repeated vertex, a duplicate) have no curvature,
  // quality or orientation to measure: the metrics are those of the others, on the same vertices.
  if (!kept) {
    const std::vector<Index> faces = enhance_detail::workable_faces(input);
    if (faces.size() != static_cast<std::size_t>(input.num_faces()) && result.F.rows() == input.F.rows()) {
      Mesh input_part, result_part;
      input_part.V = input.V;
      input_part.F = enhance_detail::face_rows(input.F, faces);
      result_part.V = result.V;
      result_part.F = enhance_detail::face_rows(result.F, faces);
      return enhance_metrics(input_part, result_part, reference, curvatures_out);
    }
  }
  // Progress (progress.h): at 1M vertices the two curvatures took about a fifth of the 8 s.
  report_progress("metrics: curvature", 0, 0.2);
  std::optional<Topology> built;
  if (!kept) built = build_topology(input.F, input.num_vertices());
  const Topology& topology = kept ? kept->topology : *built;
  // After edge flips the result has faces of its own (each keeping its index, edge_flips.h).
  const bool same_faces = result.F == input.F;
  std::optional<Topology> flipped;
  if (!same_faces) flipped = build_topology(result.F, result.num_vertices());
  const Topology& result_topology = same_faces ? topology : *flipped;

  // Each mesh's own curvature, with the estimator options compare_meshes uses by default.
  const CurvatureOptions curvature_options = CompareOptions{}.curvature;
  EnhanceCurvatures curvatures{principal_curvatures(input.V, input.F, topology, curvature_options),
                               principal_curvatures(result.V, result.F, result_topology, curvature_options)};
  // The definitions of docs/metrics.md, through the same function as `vertexflow compare`: rho
  // and the edge-error CV use the input surface's curvature at each vertex's current position.
  ComparePrecomputed precomputed;
  precomputed.result = {&result_topology, &curvatures.result};
  precomputed.input = {&topology, &curvatures.input};
  report_progress("metrics: distances", 0.2, reference ? 0.6 : 1);
  const MeshComparison c = compare_meshes(result, input, nullptr, CompareOptions{}, precomputed);
  // The flow's own unit (FlowReport::mean_edge_length is the same number).
  const double edge = mean_edge_length(input.V, topology);
  const double unit = edge > 0 ? edge : 1.0;
  const Eigen::VectorXd moved = (result.V - input.V).rowwise().norm() / unit;
  const double volume_before = signed_volume(input.V, input.F);
  nlohmann::json report;
  report["vertices"] = input.V.rows();
  report["faces"] = input.F.rows();
  // Per face index when the faces differ: flips keep each face's index (edge_flips.h).
  report["flipped_faces"] = same_faces ? (c.flipped_faces ? *c.flipped_faces : Index{0})
                                       : faces_turned_over(input.V, input.F, result.V, result.F);
  report["degenerate_faces"] = c.degenerate_faces_result;
  report["quality_input"] = c.quality_input;
  report["quality_result"] = c.quality_result;
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
  if (reference) report_progress("metrics: distances to the reference", 0.6, 1);
  if (reference)
    report["distance_to_reference"] = {{"input", distance_to(input, *reference)},
                                       {"result", distance_to(result, *reference)}};
  if (curvatures_out) *curvatures_out = std::move(curvatures);
  return report;
}

}  // namespace vertexflow
