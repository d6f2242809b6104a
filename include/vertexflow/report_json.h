// The JSON of the options and reports of the flow and the unsharp-mask baseline: one to_json
// per type (nlohmann's ADL form, so `nlohmann::json j = options;` works), written once here and
// used by `vertexflow enhance --report` and the HTML report's metrics table.
//
// Conventions
// - Every field of each struct is written, under its own name, except where stated: a test
//   (tests/report/test_report_json.cpp) fails when a field is added to a struct and not here.
// - Enumerations are written as names, never as their integer values.
// - Vertex lists (pinned vertices) are written as their count; positions are never written
//   (they go to the mesh file).
// - For nlohmann::json (ordered or other basic_json types would fall back to nlohmann's
//   integer conversion of the enumerations).
#pragma once

#include "vertexflow/curvature.h"
#include "vertexflow/distance.h"
#include "vertexflow/fit.h"
#include "vertexflow/flow.h"
#include "vertexflow/flow_energy.h"
#include "vertexflow/quality.h"
#include "vertexflow/unsharp.h"

#include <nlohmann/json.hpp>

namespace vertexflow {

/// "zero" or "input-normal" (the spellings of `vertexflow enhance --fairness`).
void to_json(nlohmann::json& j, FairnessTarget target);

/// "automatic", "direct (CHOLMOD)", "conjugate gradients" (Iterative) or "conjugate gradients,
/// multilevel" (Multilevel).
void to_json(nlohmann::json& j, LinearSolver solver);
void to_json(nlohmann::json& j, FitSolver solver);

/// "max1999", "area" or "angle".
void to_json(nlohmann::json& j, NormalWeighting weighting);

/// {lambda, mu, epsilon, fairness_target}.
void to_json(nlohmann::json& j, const EnergyWeights& weights);

/// {normal_weighting, smoothing_rounds}.
void to_json(nlohmann::json& j, const CurvatureOptions& options);

/// One flat object: the weights' keys (to_json of EnergyWeights) beside d_percentile,
/// iterations, project_to_input, feature_angle, fix_boundary, pinned (the count of pinned
/// vertices), max_halvings, min_quality, sliver_floor, curvature (an object), solver and solver_tolerance.
/// The weights are not nested so that the report keeps the keys it had before FlowOptions held
/// them as a struct (options.lambda, options.mu, ...).
void to_json(nlohmann::json& j, const FlowOptions& options);

/// Three objects, the sections of the enhance report:
/// - "solver": relative_residual (solver_error), d, mean_edge_length, method (solver_used) and
///   iterations (solver_iterations);
/// - "guard": faces_bad_before_guard (flipped_before_guard), faces_low_quality_before_guard,
///   limited_vertices and fixed_vertices;
/// - "seconds": curvature, assembly, solve, factorization, projection and guard (the
///   seconds_* fields).
void to_json(nlohmann::json& j, const FlowReport& report);

/// {weight, smoothing_iterations, fix_boundary, pinned (the count of pinned vertices)}.
void to_json(nlohmann::json& j, const UnsharpOptions& options);

/// {fixed_vertices}: what the baseline reports besides its positions V (not written).
void to_json(nlohmann::json& j, const UnsharpResult& result);

/// Every field of FitOptions (pinned as its count).
void to_json(nlohmann::json& j, const FitOptions& options);

/// Every field of SmoothSurfaceOptions.
void to_json(nlohmann::json& j, const SmoothSurfaceOptions& options);

/// Three sections, as the enhance report has them: "fit" (rms_distance, one entry for the start
/// and one per round, in the meshes' units; rounds; converged; reference_samples), "guard" (the
/// guard's counts, as the flow's) and "seconds" (per phase).
void to_json(nlohmann::json& j, const FitReport& report);

/// {min, mean, p5, fraction_below_0_3, histogram} of the radius ratios (quality.h).
void to_json(nlohmann::json& j, const QualityStats& stats);

/// {mean, rms, max} in the meshes' units, the same divided by `length_scale` (*_relative), and
/// the number of points measured (distance.h).
nlohmann::json distance_stats_json(const DistanceStats& stats, double length_scale);

}  // namespace vertexflow
