#include "vertexflow/report_json.h"

#include "vertexflow/enhance_options.h"
#include "vertexflow/remesh_report_json.h"

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

void to_json(nlohmann::json& j, FitSolver solver) {
  j = choice_name("fit_solver", static_cast<long long>(solver));
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
       {"seed", options.seed},
       {"solver", options.solver},
       {"max_solver_iterations", options.max_solver_iterations}};
}

void to_json(nlohmann::json& j, const FitReport& report) {
  j = {{"fit",
        {{"rms_distance", report.rms_distance},
         {"rounds", report.rounds},
         {"converged", report.converged},
         {"reference_samples", report.reference_samples}}},
       {"solver", {{"iterations", report.solver_iterations}, {"direct_fallbacks", report.solver_fallbacks}}},
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

// The remesh report (remesh_report_json.h): `vertexflow remesh --json` and Python's
// remesh(..., report=True).

nlohmann::json surface_repairs_json(const SurfaceRepairs& repairs) {
  return {{"input_split_vertices", repairs.input_split.held_vertices},
          {"input_reoriented_faces", repairs.input_split.reversed_faces},
          {"input_cut_edges", repairs.input_split.cut_edges},
          {"removed_degenerate_faces", repairs.removed_degenerate_faces},
          {"duplicated_vertices", repairs.duplicated_vertices}};
}

nlohmann::json remesh_cleanup_json(const RemeshCleanup& cleanup) {
  return {{"small_pieces", cleanup.small_pieces},
          {"small_piece_faces", cleanup.small_piece_faces},
          {"small_pieces_kept", cleanup.small_pieces_kept},
          {"short_loops_kept", cleanup.short_loops},
          {"held_loop_vertices", cleanup.held_loop_vertices},
          {"filled_holes", cleanup.filled_holes},
          {"collapsed_short_edges", cleanup.collapsed_short_edges},
          {"flipped_cap_edges", cleanup.flipped_cap_edges},
          {"removed_cap_faces", cleanup.removed_cap_faces}};
}

nlohmann::json remesh_report_json(const RemeshResult& result, Index input_vertices, const RemeshOptions& options,
                                  bool searched) {
  const RemeshReport& r = result.report;
  nlohmann::json out;
  out["input_vertices"] = input_vertices;
  out["vertices"] = result.mesh.num_vertices();
  out["faces"] = result.mesh.num_faces();
  if (searched) {
    out["target_vertices"] = options.target_vertices;
    out["tolerance"] = options.tolerance;
    out["within_tolerance"] = r.within_tolerance;
  }
  out["edge_length"] = r.edge_length;
  out["runs"] = nlohmann::json::array();
  for (const RemeshAttempt& a : r.attempts)
    out["runs"].push_back({{"edge_length", a.edge_length}, {"vertices", a.vertices}, {"seconds", a.seconds}});
  out["iterations"] = options.isotropic.iterations;
  out["protect_boundary"] = options.isotropic.protect_boundary;
  out["seconds"] = r.seconds;
  out["quality"] = nlohmann::json(r.quality.all);
  out["quality_interior"] = nlohmann::json(r.quality.interior);
  out["quality_rim"] = nlohmann::json(r.quality.rim);
  out["interior_faces"] = r.quality.interior_faces;
  out["rim_faces"] = r.quality.rim_faces;
  out["components"] = r.quality.components;
  out["boundary_loops"] = r.quality.boundary_loops;
  out["non_manifold_vertices"] = r.quality.non_manifold_vertices;
  out["zero_area_faces"] = r.quality.zero_area_faces;
  out["min_edge_length"] = r.quality.min_edge_length;
  out["small_piece_edges"] = options.isotropic.small_piece_edges;
  out["short_loop_edges"] = options.isotropic.short_loop_edges;
  out["fill_hole_edges"] = options.isotropic.fill_hole_edges;
  out["cleanup"] = remesh_cleanup_json(r.cleanup);
  out["repairs"] = surface_repairs_json(r.repairs);
  return out;
}

}  // namespace vertexflow
