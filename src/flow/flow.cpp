// Vertex flow (flow.h): validate, prepare (flow_setup.h), then per round estimate curvature,
// solve the normal equations (flow_solver.h), project onto the input (surface_projection.h) and
// guard against flipped, degenerate and worsened faces (guard.h).
#include "vertexflow/flow.h"

#include "../guard/guard.h"
#include "density_relaxation.h"
#include "flow_setup.h"
#include "flow_solver.h"
#include "surface_projection.h"

#include "numerics/parallel.h"
#include "vertexflow/curvature.h"
#include "vertexflow/distance.h"
#include "vertexflow/manifold_split.h"
#include "vertexflow/progress.h"
#include "vertexflow/timing.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>

namespace vertexflow {

void validate_flow_options(const FlowOptions& o, Index num_vertices) {
  auto require = [](bool ok, const char* what) {
    if (!ok) throw std::invalid_argument(std::string("vertex flow: ") + what);
  };
  const EnergyWeights& w = o.weights;
  require(std::isfinite(w.lambda) && w.lambda > 0, "lambda must be a finite number > 0");
  require(std::isfinite(w.mu) && w.mu >= 0, "mu must be a finite number >= 0");
  require(std::isfinite(w.epsilon) && w.epsilon > 0, "epsilon must be a finite number > 0");
  require(std::isfinite(w.sliver) && w.sliver >= 0, "sliver must be a finite number >= 0");
  require(o.d_percentile >= 0 && o.d_percentile <= 100, "d_percentile must be in [0, 100]");
  require(o.iterations >= 1, "iterations must be at least 1");
  require(o.feature_angle >= 0, "feature_angle must be >= 0 degrees (180 or more disables creases)");
  validate_guard_options(o.guard, "vertex flow");
  require(o.solver_tolerance > 0 && o.solver_tolerance < 1, "solver_tolerance must be in (0, 1)");
  require(o.curvature.smoothing_rounds >= 0, "curvature.smoothing_rounds must be >= 0");
  require(o.density.passes >= 0 && o.density.passes <= 1000, "density.passes must be in [0, 1000]");
  require(std::isfinite(o.density.exponent) && o.density.exponent >= 0 &&
              o.density.exponent <= DensityRelaxation::max_exponent,
          "density.exponent must be in [0, 10] (DensityRelaxation::max_exponent)");
  require(std::isfinite(o.density.epsilon) && o.density.epsilon > 0, "density.epsilon must be a finite number > 0");
  require(std::isfinite(o.density.step) && o.density.step > 0 && o.density.step <= 1, "density.step must be in (0, 1]");
  require(o.density.passes == 0 || o.project_to_input,
          "density passes need the projection (project_to_input): unprojected, the centroids shrink the mesh");
  validate_vertex_constraints(o.constraints, num_vertices, "vertex flow");
}

namespace {

// The true surface S of vertex_flow_on_reference, as the caller holds it (no copy).
struct SurfaceView {
  const Vertices& V;
  const Faces& F;
};

// `releasable`, when given, is `topology` itself, which the flow may trim (release_set_up_parts).
FlowResult check_then(const Vertices& V, const Faces& F, const Topology& topology, const FlowOptions& options,
                      const SurfaceView* reference, Topology* releasable);

// Flows the manifold split of a non-manifold or inconsistently oriented mesh (flow.h), on the
// input or on the reference: the copies of held vertices are pinned, so every input vertex has
// one position to return.
FlowResult flow_on_manifold_split(const Vertices& V, const Faces& F, const Topology& topology,
                                  const FlowOptions& options, const SurfaceView* reference) {
  const ManifoldSplit split = split_non_manifold(V, F, topology);
  FlowOptions on_split = options;
  on_split.refuse_non_manifold = true;  // the split is manifold and oriented (manifold_split.h)
  on_split.constraints.pinned.clear();
  auto pin_copies = [&](Index v) {
    for (Index s = split.first_copy[static_cast<std::size_t>(v)]; s < split.first_copy[static_cast<std::size_t>(v) + 1];
         ++s)
      on_split.constraints.pinned.push_back(s);
  };
  for (const Index v : options.constraints.pinned) pin_copies(v);
  // A crease between two vertices is one between every pair of their copies (pairs that are no
  // edge of the split are ignored).
  on_split.constraints.crease_edges.clear();
  for (const auto& [a, b] : options.constraints.crease_edges) {
    if (a < 0 || b < 0 || a >= static_cast<Index>(V.rows()) || b >= static_cast<Index>(V.rows())) continue;
    for (Index s = split.first_copy[static_cast<std::size_t>(a)]; s < split.first_copy[static_cast<std::size_t>(a) + 1];
         ++s)
      for (Index t = split.first_copy[static_cast<std::size_t>(b)];
           t < split.first_copy[static_cast<std::size_t>(b) + 1]; ++t)
        on_split.constraints.crease_edges.push_back({s, t});
  }
  for (Index v = 0; v < static_cast<Index>(V.rows()); ++v)
    if (split.held[static_cast<std::size_t>(v)]) pin_copies(v);
  Topology split_topology = build_topology(split.F, split.V.rows());
  FlowResult on_copies = check_then(split.V, split.F, split_topology, on_split, reference, &split_topology);
  FlowResult result;
  result.report = on_copies.report;
  result.V = V;
  for (Index v = 0; v < static_cast<Index>(V.rows()); ++v)
    if (!split.held[static_cast<std::size_t>(v)])
      result.V.row(v) = on_copies.V.row(split.first_copy[static_cast<std::size_t>(v)]);
  // Counted per input vertex: a held vertex's extra copies were fixed too.
  result.report.fixed_vertices -= static_cast<Index>(split.V.rows()) - static_cast<Index>(V.rows());
  result.report.held_non_manifold_vertices = split.held_vertices;
  result.report.reoriented_faces = split.reversed_faces;
  result.report.cut_edges = split.cut_non_manifold_edges + split.cut_orientation_edges;
  return result;
}

// No curvature radius below 1000 bounding-box diagonals (flow.h, kFlatCurvature): normalised
// units, where the mean edge length is 1.
bool flat_at_its_scale(const Curvature& c, const Vertices& input) {
  double largest = 0;
  for (Eigen::Index i = 0; i < c.k1.size(); ++i) largest = std::max({largest, std::abs(c.k1[i]), std::abs(c.k2[i])});
  return largest * bounding_box(input).diagonal() < kFlatCurvature;
}

// The sizing density of the density passes, refused unless finite and positive everywhere: 0 or
// inf (an extreme exponent or epsilon) gave no centroid or a NaN one, and passes that did nothing.
Eigen::VectorXd checked_density(const Curvature& c, const DensityRelaxation& options) {
  Eigen::VectorXd density = sizing_density(c, options);
  for (Eigen::Index i = 0; i < density.size(); ++i)
    if (!std::isfinite(density[i]) || !(density[i] > 0))
      throw std::invalid_argument(fmt::format(
          "vertex flow: the density passes' sizing density ({} + |k1| + |k2|)^{} is {} at vertex {} (|k1| + |k2| = "
          "{:.6g} per mean edge length); lower the exponent or raise the density epsilon",
          options.epsilon, options.exponent, density[i], i, std::abs(c.k1[i]) + std::abs(c.k2[i])));
  return density;
}

// Progress (progress.h) in units of one round, from the phases' measured costs at 1M-10M
// vertices (docs/benchmarks.md: "Peak RSS and wall time by phase", the size ladder, "Density
// passes"): the set-up a tenth of a round, a density pass 0.15; within a round the curvature
// 5%, the solve (assembly, preconditioner, iterations) 80%, the projection 8%, the guard 7%.
constexpr double kSetUpUnits = 0.1, kDensityPassUnits = 0.15;
constexpr double kSolveStarts = 0.05, kProjectionStarts = 0.85, kGuardStarts = 0.93;

// What the flow reads of the topology after its set-up: the edges, rings, vertex faces and
// boundary flags (curvature, flow terms, projection, guard, density passes). The rest served
// prepare_flow's features only: 73 bytes per vertex (face edges 24, face adjacency 24, edge
// face counts 12, components 12, manifold flags 1) that the solve, the peak, need not hold.
void release_set_up_parts(Topology& topology) {
  topology.face_edges.resize(0, 3);
  topology.face_adjacency.resize(0, 3);
  std::vector<Index>().swap(topology.edge_face_count);
  std::vector<Index>().swap(topology.vertex_component);
  std::vector<Index>().swap(topology.face_component);
  std::vector<std::uint8_t>().swap(topology.is_manifold_vertex);
}

// The rounds of vertex_flow on a manifold, oriented mesh with valid options: on the input, or
// with frames, curvature and projection from the reference S (vertex_flow_on_reference).
FlowResult flow_rounds(const Vertices& V, const Faces& F, const Topology& topology, const FlowOptions& options,
                       const SurfaceView* reference, Topology* releasable) {
  const Index n = static_cast<Index>(V.rows());
  FlowResult result;
  FlowReport& report = result.report;
  const double units = kSetUpUnits + options.iterations + kDensityPassUnits * options.density.passes;
  auto progress = [&](const std::string& phase, double from, double to) {
    report_progress(phase, from / units, to / units);
  };
  // "solve" or, over several rounds, "solve (round 2/3)".
  auto in_round = [&](const char* phase, int round) {
    return options.iterations > 1 ? fmt::format("{} (round {}/{})", phase, round + 1, options.iterations)
                                  : std::string(phase);
  };
  progress(reference ? "flow set-up, reference surface" : "flow set-up", 0, kSetUpUnits);

  FlowSetup setup = prepare_flow(V, F, topology, options);
  if (releasable) release_set_up_parts(*releasable);
  std::optional<ReferenceSurface> surface;
  if (reference) {  // S in the flow's normalised units
    const Vertices VS = normalised(reference->V, setup);
    surface.emplace(ReferenceSurface{
        DistanceQuery(VS, reference->F),
        principal_curvatures(VS, reference->F, build_topology(reference->F, VS.rows()), options.curvature)});
  }
  const std::vector<char>& fixed = setup.fixed;
  const Vertices& input = setup.input;
  report.fixed_vertices = static_cast<Index>(std::count(fixed.begin(), fixed.end(), 1));
  report.mean_edge_length = setup.mean_edge_length;

  Vertices X = copy_rows_in_parallel(input);
  // One solver for all rounds: the connectivity is fixed, so its ordering is computed once.
  FlowSystemSolver solver(topology, fixed, options.solver, options.solver_tolerance);
  // Computed at the first guard, after the first solve: 16 bytes per vertex fewer at its peak.
  std::optional<GuardCriteria> criteria_once;
  auto criteria = [&]() -> const GuardCriteria& {
    if (!criteria_once) criteria_once.emplace(guard_criteria(input, F, options.guard));
    return *criteria_once;
  };
  std::vector<char> shortened(static_cast<std::size_t>(n), 0);
  std::vector<Index> free_rows;
  free_rows.reserve(static_cast<std::size_t>(n) - static_cast<std::size_t>(report.fixed_vertices));
  for (Index i = 0; i < n; ++i) {
    if (!fixed[static_cast<std::size_t>(i)]) free_rows.push_back(i);
  }
  std::vector<Index> projected_rows;  // free_rows in the solve's order, after the first solve
  // Free vertices onto the surface the flow runs on: S, or the input (features respected).
  auto project = [&](Vertices& Y, const std::vector<Index>& rows) {
    if (surface) {
      const std::vector<ClosestPoint> feet = surface->query.closest_points(Y);
      for (const Index i : rows) Y.row(i) = feet[static_cast<std::size_t>(i)].point.transpose();
    } else {
      restore_after_solve(setup, V, F);  // the features' normals, if no solve has restored them yet
      project_near_vertices(Y, rows, input, F, topology, setup.features);
    }
  };
  // The guard puts the vertices it shortens back onto the input (those of the flow on S are not
  // projected onto S).
  Reprojection reproject;
  if (options.project_to_input && !surface) reproject = project;
  // The sizing density of the density passes, from the surface's curvature at the input positions.
  Eigen::VectorXd density;
  for (int round = 0; round < options.iterations; ++round) {
    // X at the start of the round, for the guard. The input's frame holds a copy of X as its P
    // (flow_setup.h) and the solve leaves P in place, so only S's frame, whose P is X's foot
    // points on S, needs a copy of its own: 24 bytes per vertex fewer at the solve, the peak.
    Vertices start_copy;
    if (surface) start_copy = X;
    const double at = kSetUpUnits + round;
    progress(in_round("curvature", round), at, at + kSolveStarts);
    // One solve: minimise the energy for positions X, frozen curvature of X.
    auto start = Clock::now();
    FlowFrame frame = surface ? flow_frame_on_reference(X, F, topology, options, setup.sliver_faces, *surface, fixed)
                              : flow_frame(X, F, topology, options, setup.sliver_faces);
    const Vertices& start_of_round = surface ? start_copy : frame.P;
    if (round == 0 && options.density.passes > 0) density = checked_density(frame.curvature, options.density);
    report.d = frame.d;
    report.seconds_curvature += seconds_since(start);
    // Nothing to enhance (flow.h): the input stays; on S the vertices are only put onto it.
    if (round == 0 && flat_at_its_scale(frame.curvature, input)) {
      report.flat = true;
      if (surface && options.project_to_input) {
        project(X, free_rows);
        guard(X, start_of_round, criteria(), fixed, topology, options.guard, reproject, shortened);
      }
      break;
    }
    // X equals start_of_round here: freed for the solve, whose peak is the run's, as is what
    // the solve does not read of the set-up.
    Vertices().swap(X);
    release_during_solve(setup);
    {
      // The solver reports its iterations within this part (flow_solver.h).
      const std::string phase = in_round("solve", round);
      const ProgressPart part(phase, (at + kSolveStarts) / units, (at + kProjectionStarts) / units);
      solver.set_progress_phase(phase);
      X = solver.solve_releasing(frame, options.weights, report);  // frees its curvature once assembled
    }
    restore_after_solve(setup, V, F);
    if (!X.allFinite()) throw std::runtime_error("vertex flow: the solver diverged");
    if (options.project_to_input) {
      progress(in_round("projection", round), at + kProjectionStarts, at + kGuardStarts);
      start = Clock::now();
      // The free vertices in the solve's order (neighbours close together), so that consecutive
      // walks find the faces and positions they read in the cache: the same points in any
      // order, 13% faster on the 1M armadillo, whose vertices the splitting numbered far apart.
      if (projected_rows.empty() && solver.vertex_order().size() == static_cast<std::size_t>(n))
        for (const Index i : solver.vertex_order())
          if (!fixed[static_cast<std::size_t>(i)]) projected_rows.push_back(i);
      project(X, projected_rows.size() == free_rows.size() ? projected_rows : free_rows);
      report.seconds_projection += seconds_since(start);
    }
    // Guarded after every round, not only the last: the next round's curvature is estimated on
    // X, and on the unguarded fandisk after three rounds (671 flipped or degenerate faces) it
    // reached 1e15 per mean edge length, which made the normal matrix numerically indefinite.
    progress(in_round("guard", round), at + kGuardStarts, at + 1);
    start = Clock::now();
    const GuardCounts counts =
        guard(X, start_of_round, criteria(), fixed, topology, options.guard, reproject, shortened);
    report.flipped_before_guard += counts.flipped_before_guard;
    report.low_quality_before_guard += counts.low_quality_before_guard;
    report.seconds_guard += seconds_since(start);
  }

  if (options.density.passes > 0) {
    // FlowOptions::density: each pass proposed, projected and guarded as a solve is. Its own
    // counts: the passes' small steps are shortened far more often than a solve's, and the
    // guard's before-counts describe the solves.
    const auto start = Clock::now();
    std::vector<char> density_shortened(static_cast<std::size_t>(n), 0);
    // Free boundary vertices (fix_boundary false) stay where the solve put them: their centroid
    // lies inside the surface, and nothing would hold them on the boundary line.
    std::vector<Index> interior_rows;
    for (const Index i : free_rows)
      if (!topology.is_boundary_vertex[static_cast<std::size_t>(i)]) interior_rows.push_back(i);
    for (int pass = 0; pass < options.density.passes; ++pass) {
      const double at = kSetUpUnits + options.iterations + kDensityPassUnits * pass;
      progress(fmt::format("density pass {}/{}", pass + 1, options.density.passes), at, at + kDensityPassUnits);
      const Vertices start_of_pass = X;
      X = density_pass_proposal(X, F, topology, density, interior_rows, options.density.step);
      project(X, interior_rows);  // only the moved rows: the Phong lift is not idempotent
      guard(X, start_of_pass, criteria(), fixed, topology, options.guard, reproject, density_shortened);
    }
    report.density_limited_vertices =
        static_cast<Index>(std::count(density_shortened.begin(), density_shortened.end(), 1));
    report.seconds_density = seconds_since(start);
  }

  report.limited_vertices = static_cast<Index>(std::count(shortened.begin(), shortened.end(), 1));
  report.d *= setup.scale;

  // A flat surface's unmoved vertices come back bit for bit, not through the normalisation's round trip.
  if (report.flat && X == input)
    result.V = V;
  else
    result.V = denormalised(X, setup);
  // Fixed vertices are returned bit for bit.
  for (Index i = 0; i < n; ++i) {
    if (fixed[static_cast<std::size_t>(i)]) result.V.row(i) = V.row(i);
  }
  return result;
}

}  // namespace

FlowResult vertex_flow(const Vertices& V, const Faces& F, const FlowOptions& options) {
  // Options are validated by the overload below; the topology needs a non-empty mesh first.
  if (V.rows() == 0 || F.rows() == 0) throw std::invalid_argument("vertex flow: the mesh is empty");
  return vertex_flow(V, F, build_topology(F, static_cast<Index>(V.rows())), options);
}

namespace {

// vertex_flow's checks, then the rounds (on the manifold split of a non-manifold mesh when
// options allow), on the input or on the reference.
FlowResult check_then(const Vertices& V, const Faces& F, const Topology& topology, const FlowOptions& options,
                      const SurfaceView* reference, Topology* releasable) {
  const Index n = static_cast<Index>(V.rows());
  validate_flow_options(options, n);
  if (n == 0 || F.rows() == 0) throw std::invalid_argument("vertex flow: the mesh is empty");
  if (topology.num_vertices != n || topology.num_faces != static_cast<Index>(F.rows()))
    throw std::invalid_argument("vertex flow: the topology was built for another mesh");
  if (!V.allFinite()) throw std::invalid_argument("vertex flow: a vertex has a non-finite coordinate");
  // The flow normalises by the mean edge length and judges faces relative to the diagonal; a
  // mesh without extent has neither.
  if (!(bounding_box(V).diagonal() > 0))
    throw std::invalid_argument(
        "vertex flow: the bounding box has zero size (all vertices at one point, or coordinates too small to compute "
        "with)");
  if (!topology.is_manifold() || !topology.is_oriented) {
    if (options.refuse_non_manifold)
      throw std::invalid_argument("vertex flow: " + (topology.is_manifold()
                                                         ? std::string("the faces are not consistently oriented")
                                                         : describe_non_manifold(topology)));
    return flow_on_manifold_split(V, F, topology, options, reference);
  }
  return flow_rounds(V, F, topology, options, reference, releasable);
}

}  // namespace

FlowResult vertex_flow(const Vertices& V, const Faces& F, const Topology& topology, const FlowOptions& options) {
  return check_then(V, F, topology, options, nullptr, nullptr);
}

FlowResult vertex_flow(const Vertices& V, const Faces& F, Topology&& topology, const FlowOptions& options) {
  return check_then(V, F, topology, options, nullptr, &topology);
}

FlowResult vertex_flow_on_reference(const Vertices& V, const Faces& F, const Vertices& VS, const Faces& FS,
                                    const FlowOptions& options) {
  if (VS.rows() == 0 || FS.rows() == 0)
    throw std::invalid_argument("vertex flow on a reference: the reference is empty");
  if (!VS.allFinite())
    throw std::invalid_argument("vertex flow on a reference: a vertex of the reference has a non-finite coordinate");
  if (V.rows() == 0 || F.rows() == 0) throw std::invalid_argument("vertex flow: the mesh is empty");
  Topology topology = build_topology(F, static_cast<Index>(V.rows()));
  const SurfaceView reference{VS, FS};
  return check_then(V, F, topology, options, &reference, &topology);
}

}  // namespace vertexflow
