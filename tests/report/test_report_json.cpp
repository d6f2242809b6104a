// report_json.h: every field of every struct is in its JSON, under its name, with its value.
//
// Each test binds every field of its struct by name (a structured binding needs exactly as
// many names as the struct has fields), so adding a field stops this file from compiling until
// the field is named here, given a non-default value and expected in the JSON.
#include "vertexflow/remesh_report_json.h"
#include "vertexflow/report_json.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <set>
#include <string>

namespace vertexflow {
namespace {

std::set<std::string> keys(const nlohmann::json& j) {
  std::set<std::string> out;
  for (const auto& [key, value] : j.items()) out.insert(key);
  return out;
}

// Every key of `changed` has a value other than in `defaults`: each key follows its field.
void expect_every_value_differs(const nlohmann::json& changed, const nlohmann::json& defaults) {
  ASSERT_EQ(keys(changed), keys(defaults));
  for (const auto& [key, value] : changed.items()) EXPECT_NE(value, defaults[key]) << key;
}

TEST(ReportJson, EnumerationsAreNames) {
  EXPECT_EQ(nlohmann::json(FairnessTarget::Zero), "zero");
  EXPECT_EQ(nlohmann::json(FairnessTarget::InputNormal), "input-normal");
  EXPECT_EQ(nlohmann::json(LinearSolver::Automatic), "automatic");
  EXPECT_EQ(nlohmann::json(LinearSolver::Direct), "direct (CHOLMOD)");
  EXPECT_EQ(nlohmann::json(LinearSolver::Iterative), "conjugate gradients");
  EXPECT_EQ(nlohmann::json(LinearSolver::Multilevel), "conjugate gradients, multilevel");
  EXPECT_EQ(nlohmann::json(NormalWeighting::Max1999), "max1999");
  EXPECT_EQ(nlohmann::json(NormalWeighting::Area), "area");
  EXPECT_EQ(nlohmann::json(NormalWeighting::Angle), "angle");
}

TEST(ReportJson, EnergyWeightsEveryField) {
  EnergyWeights weights;
  auto& [lambda, mu, epsilon, fairness_target, sliver] = weights;
  lambda = 0.25;
  mu = 0.75;
  epsilon = 1e-4;
  fairness_target = FairnessTarget::Zero;
  sliver = 0.5;
  const nlohmann::json j = weights;
  EXPECT_EQ(j, nlohmann::json::parse(
                   R"({"lambda": 0.25, "mu": 0.75, "epsilon": 1e-4, "fairness_target": "zero", "sliver": 0.5})"));
  expect_every_value_differs(j, EnergyWeights{});
}

TEST(ReportJson, CurvatureOptionsEveryField) {
  CurvatureOptions options;
  auto& [normal_weighting, smoothing_rounds] = options;
  normal_weighting = NormalWeighting::Angle;
  smoothing_rounds = 2;
  const nlohmann::json j = options;
  EXPECT_EQ(j, nlohmann::json::parse(R"({"normal_weighting": "angle", "smoothing_rounds": 2})"));
  expect_every_value_differs(j, CurvatureOptions{});
}

TEST(ReportJson, FlowOptionsEveryField) {
  FlowOptions options;
  auto& [weights, d_percentile, iterations, project_to_input, feature_angle, constraints, refuse_non_manifold, guard,
         curvature, solver, solver_tolerance, density] = options;
  auto& [fix_boundary, pinned, crease_edges] = constraints;
  auto& [min_quality, sliver_floor, max_halvings] = guard;
  weights.lambda = 0.25;
  weights.mu = 0.75;
  weights.epsilon = 1e-4;
  weights.fairness_target = FairnessTarget::Zero;
  weights.sliver = 0.5;
  d_percentile = 95;
  iterations = 3;
  project_to_input = false;
  feature_angle = 30;
  fix_boundary = false;
  pinned = {4, 8, 15};
  crease_edges = {{1, 2}};
  refuse_non_manifold = true;
  max_halvings = 12;
  min_quality = 0.2;
  sliver_floor = 0.25;
  curvature.normal_weighting = NormalWeighting::Area;
  curvature.smoothing_rounds = 1;
  solver = LinearSolver::Multilevel;
  solver_tolerance = 1e-9;
  auto& [passes, exponent, epsilon, step] = density;
  passes = 12;
  exponent = 1.5;
  epsilon = 0.25;
  step = 0.75;
  const nlohmann::json j = options;
  // The weights' keys stay at the top level, where the report has always had them.
  EXPECT_EQ(j, nlohmann::json::parse(R"({
    "lambda": 0.25, "mu": 0.75, "epsilon": 1e-4, "fairness_target": "zero", "sliver": 0.5,
    "d_percentile": 95.0, "iterations": 3, "project_to_input": false, "feature_angle": 30.0,
    "fix_boundary": false, "pinned": 3, "crease_edges": 1, "refuse_non_manifold": true, "max_halvings": 12,
    "min_quality": 0.2,
    "sliver_floor": 0.25,
    "curvature": {"normal_weighting": "area", "smoothing_rounds": 1},
    "solver": "conjugate gradients, multilevel", "solver_tolerance": 1e-9,
    "density": {"passes": 12, "exponent": 1.5, "epsilon": 0.25, "step": 0.75}})"));
  expect_every_value_differs(j, FlowOptions{});
  for (const auto& [key, value] : j["curvature"].items()) EXPECT_NE(value, nlohmann::json(CurvatureOptions{})[key]);
  for (const auto& [key, value] : j["density"].items()) EXPECT_NE(value, nlohmann::json(FlowOptions{})["density"][key]);
}

TEST(ReportJson, FlowReportEveryFieldInItsSection) {
  FlowReport report;
  auto& [mean_edge_length, d, solver_error, flipped_before_guard, low_quality_before_guard, limited_vertices,
         density_limited_vertices, fixed_vertices, held_non_manifold_vertices, reoriented_faces, cut_edges,
         seconds_curvature, seconds_assembly, seconds_solve, seconds_projection, seconds_guard, seconds_density,
         seconds_factorization, solver_used, solver_iterations, flat] = report;
  mean_edge_length = 0.5;
  d = 2.5;
  solver_error = 1e-8;
  flipped_before_guard = 1;
  low_quality_before_guard = 2;
  limited_vertices = 3;
  density_limited_vertices = 8;
  fixed_vertices = 4;
  held_non_manifold_vertices = 5;
  reoriented_faces = 6;
  cut_edges = 7;
  seconds_curvature = 0.125;
  seconds_assembly = 0.25;
  seconds_solve = 0.375;
  seconds_projection = 0.5;
  seconds_guard = 0.625;
  seconds_density = 0.875;
  seconds_factorization = 0.75;
  solver_used = LinearSolver::Direct;
  solver_iterations = 42;
  flat = true;
  const nlohmann::json j = report;
  const nlohmann::json expected = {{"solver",
                                    {{"relative_residual", 1e-8},
                                     {"d", 2.5},
                                     {"mean_edge_length", 0.5},
                                     {"method", "direct (CHOLMOD)"},
                                     {"iterations", 42},
                                     {"flat", true}}},
                                   {"guard",
                                    {{"faces_bad_before_guard", 1},
                                     {"faces_low_quality_before_guard", 2},
                                     {"limited_vertices", 3},
                                     {"density_limited_vertices", 8},
                                     {"fixed_vertices", 4}}},
                                   {"non_manifold", {{"held_vertices", 5}, {"reoriented_faces", 6}, {"cut_edges", 7}}},
                                   {"seconds",
                                    {{"curvature", 0.125},
                                     {"assembly", 0.25},
                                     {"solve", 0.375},
                                     {"projection", 0.5},
                                     {"guard", 0.625},
                                     {"density", 0.875},
                                     {"factorization", 0.75}}}};
  EXPECT_EQ(j, expected);
  const nlohmann::json defaults = FlowReport{};
  for (const char* section : {"solver", "guard", "non_manifold", "seconds"})
    expect_every_value_differs(j[section], defaults[section]);
}

TEST(ReportJson, UnsharpOptionsAndResultEveryField) {
  UnsharpOptions options;
  auto& [weight, smoothing_iterations, constraints, refuse_non_manifold] = options;
  auto& [fix_boundary, pinned, crease_edges] = constraints;
  weight = 0.5;
  smoothing_iterations = 7;
  fix_boundary = false;
  pinned = {1, 2};
  crease_edges = {{1, 2}, {2, 3}};
  refuse_non_manifold = true;
  const nlohmann::json j = options;
  EXPECT_EQ(j, nlohmann::json::parse(R"({"weight": 0.5, "smoothing_iterations": 7, "fix_boundary": false,
                                         "pinned": 2, "crease_edges": 2, "refuse_non_manifold": true})"));
  expect_every_value_differs(j, UnsharpOptions{});

  UnsharpResult result;
  auto& [V, fixed_vertices, non_manifold] = result;
  V = Vertices::Ones(3, 3);  // positions are for the mesh file, not the report
  fixed_vertices = 9;
  non_manifold = {4, 5, 6};
  EXPECT_EQ(nlohmann::json(result), nlohmann::json::parse(R"({"fixed_vertices": 9, "non_manifold":
                                    {"held_vertices": 4, "reoriented_faces": 5, "cut_edges": 6}})"));
}

// remesh_report_json.h: what `vertexflow remesh --json` prints and Python's remesh(report=True)
// returns. Every field of RemeshCleanup, SurfaceRepairs and RemeshQuality, each value its own.
TEST(ReportJson, RemeshReportEveryField) {
  RemeshResult result;
  result.mesh.V = Vertices::Zero(5, 3);
  result.mesh.F = Faces::Zero(7, 3);
  RemeshReport& r = result.report;
  r.attempts = {{0.5, 4, 0.25}, {0.625, 5, 0.375}};
  r.edge_length = 0.625;
  r.within_tolerance = true;
  r.seconds = 0.75;
  auto& [input_split, removed_degenerate_faces, duplicated_vertices] = r.repairs;
  auto& [held_vertices, reversed_faces, cut_edges] = input_split;
  held_vertices = 1;
  reversed_faces = 2;
  cut_edges = 3;
  removed_degenerate_faces = 4;
  duplicated_vertices = 5;
  auto& [small_pieces, small_piece_faces, small_pieces_kept, short_loops, held_loop_vertices, filled_holes,
         collapsed_short_edges, flipped_cap_edges, removed_cap_faces] = r.cleanup;
  small_pieces = 11;
  small_piece_faces = 12;
  small_pieces_kept = true;
  short_loops = 13;
  held_loop_vertices = 14;
  filled_holes = 15;
  collapsed_short_edges = 16;
  flipped_cap_edges = 17;
  removed_cap_faces = 18;
  auto& [all, interior, rim, interior_faces, rim_faces, components, boundary_loops, non_manifold_vertices,
         zero_area_faces, min_edge_length] = r.quality;
  all.min = 0.125;
  interior.min = 0.25;
  rim.min = 0.375;
  interior_faces = 21;
  rim_faces = 22;
  components = 23;
  boundary_loops = 24;
  non_manifold_vertices = 25;
  zero_area_faces = 26;
  min_edge_length = 0.0625;
  RemeshOptions options;
  options.target_vertices = 6;
  options.tolerance = 0.5;
  options.isotropic.iterations = 3;
  options.isotropic.protect_boundary = true;
  options.isotropic.small_piece_edges = 4.5;
  options.isotropic.short_loop_edges = 5.5;
  options.isotropic.fill_hole_edges = 6.5;

  nlohmann::json expected = nlohmann::json::parse(R"({
    "input_vertices": 40, "vertices": 5, "faces": 7, "target_vertices": 6, "tolerance": 0.5,
    "within_tolerance": true, "edge_length": 0.625,
    "runs": [{"edge_length": 0.5, "vertices": 4, "seconds": 0.25},
             {"edge_length": 0.625, "vertices": 5, "seconds": 0.375}],
    "iterations": 3, "protect_boundary": true, "seconds": 0.75,
    "interior_faces": 21, "rim_faces": 22, "components": 23, "boundary_loops": 24,
    "non_manifold_vertices": 25, "zero_area_faces": 26, "min_edge_length": 0.0625,
    "small_piece_edges": 4.5, "short_loop_edges": 5.5, "fill_hole_edges": 6.5,
    "cleanup": {"small_pieces": 11, "small_piece_faces": 12, "small_pieces_kept": true,
                "short_loops_kept": 13, "held_loop_vertices": 14, "filled_holes": 15,
                "collapsed_short_edges": 16, "flipped_cap_edges": 17, "removed_cap_faces": 18},
    "repairs": {"input_split_vertices": 1, "input_reoriented_faces": 2, "input_cut_edges": 3,
                "removed_degenerate_faces": 4, "duplicated_vertices": 5}})");
  expected["quality"] = nlohmann::json(all);
  expected["quality_interior"] = nlohmann::json(interior);
  expected["quality_rim"] = nlohmann::json(rim);
  const nlohmann::json j = remesh_report_json(result, 40, options, /*searched=*/true);
  EXPECT_EQ(j, expected);
  expect_every_value_differs(j["cleanup"], remesh_cleanup_json(RemeshCleanup{}));
  expect_every_value_differs(j["repairs"], surface_repairs_json(SurfaceRepairs{}));
  EXPECT_NE(j["quality"], j["quality_interior"]);
  EXPECT_NE(j["quality_interior"], j["quality_rim"]);

  // A run at one edge length (remesh_to_edge_length) searched no count: no target, tolerance or
  // within_tolerance.
  for (const char* key : {"target_vertices", "tolerance", "within_tolerance"}) expected.erase(key);
  EXPECT_EQ(remesh_report_json(result, 40, options, /*searched=*/false), expected);
}
}  // namespace
}  // namespace vertexflow
