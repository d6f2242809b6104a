#include "vertexflow/report_json.h"

#include "vertexflow/enhance_options.h"

#include <nlohmann/json.hpp>

namespace vertexflow {

// The enumerations' names are the option table's (enhance_options.h), written once there.
void to_json(nlohmann::json& j, FairnessTarget target) {
  j = choice_name("fairness_target", static_cast<long long>(target));
}

void to_json(nlohmann::json& j, LinearSolver solver) {
  switch (solver) {
    case LinearSolver::Automatic:
      j = "automatic";
      return;
    case LinearSolver::Direct:
      j = "direct (CHOLMOD)";
      return;
    case LinearSolver::Iterative:
      j = "conjugate gradients";
      return;
    case LinearSolver::Multilevel:
      j = "conjugate gradients, multilevel";
      return;
  }
  j = "?";
}

void to_json(nlohmann::json& j, NormalWeighting weighting) {
  j = choice_name("normal_weighting", static_cast<long long>(weighting));
}

void to_json(nlohmann::json& j, const EnergyWeights& weights) {
  j = {{"lambda", weights.lambda},
       {"mu", weights.mu},
       {"epsilon", weights.epsilon},
       {"sliver", weights.sliver},
       {"fairness_target", weights.fairness_target}};
}

void to_json(nlohmann::json& j, const CurvatureOptions& options) {
  j = {{"normal_weighting", options.normal_weighting}, {"smoothing_rounds", options.smoothing_rounds}};
}

void to_json(nlohmann::json& j, const FlowOptions& options) {
  j = options.weights;
  j.update({{"d_percentile", options.d_percentile},
            {"iterations", options.iterations},
            {"project_to_input", options.project_to_input},
            {"feature_angle", options.feature_angle},
            {"fix_boundary", options.constraints.fix_boundary},
            {"pinned", options.constraints.pinned.size()},
            {"crease_edges", options.constraints.crease_edges.size()},
            {"refuse_non_manifold", options.refuse_non_manifold},
            {"max_halvings", options.guard.max_halvings},
            {"min_quality", options.guard.min_quality},
            {"sliver_floor", options.guard.sliver_floor},
            {"curvature", options.curvature},
            {"solver", options.solver},
            {"solver_tolerance", options.solver_tolerance},
            {"density",
             {{"passes", options.density.passes},
              {"exponent", options.density.exponent},
              {"epsilon", options.density.epsilon},
              {"step", options.density.step}}}});
}

void to_json(nlohmann::json& j, const FlowReport& report) {
  j = {{"solver",
        {{"relative_residual", report.solver_error},
         {"d", report.d},
         {"mean_edge_length", report.mean_edge_length},
         {"method", report.solver_used},
         {"iterations", report.solver_iterations},
         {"flat", report.flat}}},
       {"guard",
        {{"faces_bad_before_guard", report.flipped_before_guard},
         {"faces_low_quality_before_guard", report.low_quality_before_guard},
         {"limited_vertices", report.limited_vertices},
         {"density_limited_vertices", report.density_limited_vertices},
         {"fixed_vertices", report.fixed_vertices}}},
       {"non_manifold",
        {{"held_vertices", report.held_non_manifold_vertices},
         {"reoriented_faces", report.reoriented_faces},
         {"cut_edges", report.cut_edges}}},
       {"seconds",
        {{"curvature", report.seconds_curvature},
         {"assembly", report.seconds_assembly},
         {"solve", report.seconds_solve},
         {"factorization", report.seconds_factorization},
         {"projection", report.seconds_projection},
         {"guard", report.seconds_guard},
         {"density", report.seconds_density}}}};
}

void to_json(nlohmann::json& j, const UnsharpOptions& options) {
  j = {{"weight", options.weight},
       {"smoothing_iterations", options.smoothing_iterations},
       {"fix_boundary", options.constraints.fix_boundary},
       {"pinned", options.constraints.pinned.size()},
       {"crease_edges", options.constraints.crease_edges.size()},
       {"refuse_non_manifold", options.refuse_non_manifold}};
}

void to_json(nlohmann::json& j, const UnsharpResult& result) {
  j = {{"fixed_vertices", result.fixed_vertices},
       {"non_manifold",
        {{"held_vertices", result.non_manifold.held_vertices},
         {"reoriented_faces", result.non_manifold.reversed_faces},
         {"cut_edges", result.non_manifold.cut_edges}}}};
}

void to_json(nlohmann::json& j, const FitOptions& options) {
  j = {{"samples_per_vertex", options.samples_per_vertex},
       {"mesh_to_reference_weight", options.mesh_to_reference_weight},
       {"fairness", options.fairness},
       {"proximity", options.proximity},
       {"max_rounds", options.max_rounds},
       {"tolerance", options.tolerance},
       {"fix_boundary", options.constraints.fix_boundary},
       {"pinned", options.constraints.pinned.size()},
       {"crease_edges", options.constraints.crease_edges.size()},
       {"min_quality", options.guard.min_quality},
       {"sliver_floor", options.guard.sliver_floor},
       {"seed", options.seed}};
}

void to_json(nlohmann::json& j, const FitReport& report) {
  j = {{"fit",
        {{"rms_distance", report.rms_distance},
         {"rounds", report.rounds},
         {"converged", report.converged},
         {"reference_samples", report.reference_samples}}},
       {"guard",
        {{"faces_bad_before_guard", report.flipped_before_guard},
         {"faces_low_quality_before_guard", report.low_quality_before_guard},
         {"limited_vertices", report.limited_vertices}}},
       {"seconds",
        {{"tree", report.seconds_tree},
         {"queries", report.seconds_queries},
         {"solve", report.seconds_solve},
         {"guard", report.seconds_guard},
         {"surface", report.seconds_surface}}}};
}

void to_json(nlohmann::json& j, const QualityStats& stats) {
  j = {{"min", stats.min},
       {"mean", stats.mean},
       {"p5", stats.p5},
       {"fraction_below_0_3", stats.fraction_below_0_3},
       {"histogram", stats.histogram}};
}

nlohmann::json distance_stats_json(const DistanceStats& stats, double length_scale) {
  return {{"mean", stats.mean},
          {"rms", stats.rms},
          {"max", stats.max},
          {"mean_relative", stats.mean / length_scale},
          {"rms_relative", stats.rms / length_scale},
          {"max_relative", stats.max / length_scale},
          {"points", stats.points}};
}

void to_json(nlohmann::json& j, const SmoothSurfaceOptions& options) {
  j = {{"segments", options.segments}, {"feature_angle", options.feature_angle}};
}

}  // namespace vertexflow
