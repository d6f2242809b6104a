// Vertex flow: normalise, estimate curvature, assemble (flow_energy.cpp), solve the normal
// equations, then guard against flipped and degenerate faces.
#include "vertexflow/flow.h"

#include "flow_solver.h"
#include "surface_projection.h"
#include "vertexflow/flow_energy.h"
#include "vertexflow/quality.h"
#include "vertexflow/statistics.h"
#include "vertexflow/timing.h"
#include "vertexflow/topology.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>

namespace vertexflow {
namespace {

// The radius d of Eq. 6: 1 / (percentile of the largest |k| per vertex).
double robust_radius(const Curvature& c, double at_percentile) {
  std::vector<double> k(static_cast<std::size_t>(c.k1.size()));
  for (Eigen::Index i = 0; i < c.k1.size(); ++i)
    k[static_cast<std::size_t>(i)] = std::max(std::abs(c.k1[i]), std::abs(c.k2[i]));
  const double largest = percentile(std::move(k), at_percentile);
  return largest > 0 ? 1.0 / largest : 1.0;
}

// What the guard repairs (flow.h, FlowOptions::min_quality): faces that turned by more than
// 90 degrees, became degenerate, or whose radius ratio fell below min(min_quality, their
// input's). Faces already degenerate in `before` cannot be judged (no normal) and are never
// bad: returning their vertices to the input restores them, so the guard could not repair them.
struct GuardCriteria {
  const Vertices& before;
  const Faces& F;
  double min_area = 0;
  Eigen::VectorXd quality_floor;  // per face; a face is bad below it
};

GuardCriteria guard_criteria(const Vertices& before, const Faces& F, double min_quality) {
  const double diagonal = bounding_box(before).diagonal();
  GuardCriteria criteria{before, F, kDegenerateAreaRelative * diagonal * diagonal, triangle_quality(before, F)};
  criteria.quality_floor = criteria.quality_floor.cwiseMin(min_quality);
  return criteria;
}

constexpr char kFlippedOrDegenerate = 1, kLowQuality = 2;

char face_badness(const GuardCriteria& criteria, const Vertices& after, Index f) {
  const Faces& F = criteria.F;
  const Eigen::Vector3d n0 = face_normal(criteria.before, F, f), n1 = face_normal(after, F, f);
  // Written as !(>) so that a zero-area face is never judged, even where min_area is 0.
  if (!(0.5 * n0.norm() > criteria.min_area)) return 0;
  if (n0.dot(n1) <= 0 || 0.5 * n1.norm() < criteria.min_area) return kFlippedOrDegenerate;
  const Eigen::Vector3d a = after.row(F(f, 0)), b = after.row(F(f, 1)), c = after.row(F(f, 2));
  return triangle_quality(a, b, c) < criteria.quality_floor[f] ? kLowQuality : 0;
}

std::vector<char> bad_faces(const GuardCriteria& criteria, const Vertices& after) {
  std::vector<char> bad(static_cast<std::size_t>(criteria.F.rows()), 0);
  tbb::parallel_for(tbb::blocked_range<Index>(0, static_cast<Index>(criteria.F.rows()), 4096),
                    [&](const tbb::blocked_range<Index>& r) {
                      for (Index f = r.begin(); f != r.end(); ++f)
                        bad[static_cast<std::size_t>(f)] = face_badness(criteria, after, f);
                    });
  return bad;
}

// Guard (flow.h): halve the displacement from `anchor` (the positions before the round, not
// bad) of every vertex of a bad face until no face is bad. Counts the bad faces in report
// (summed over rounds) and marks the vertices it shortened.
void guard(Vertices& X, const Vertices& anchor, const Vertices& input, const GuardCriteria& criteria,
           const std::vector<char>& fixed, const Topology& topology, const SurfaceFeatures& features,
           const FlowOptions& options, std::vector<char>& shortened, FlowReport& report) {
  const Faces& F = criteria.F;
  const Index n = static_cast<Index>(X.rows());
  const Vertices displacement = X - anchor;
  std::vector<double> step(static_cast<std::size_t>(n), 1.0);
  std::vector<char> bad = bad_faces(criteria, X);
  report.flipped_before_guard += static_cast<Index>(std::count(bad.begin(), bad.end(), kFlippedOrDegenerate));
  report.low_quality_before_guard += static_cast<Index>(std::count(bad.begin(), bad.end(), kLowQuality));
  // Each round halves every free vertex of a bad face once; after max_halvings rounds their
  // displacement is zero, and a face whose vertices are all back at the anchor is not bad. Only
  // the faces around the vertices a round moved are judged again. The loop ends when a round
  // changes no step: steps only ever shrink, through at most max_halvings values each, so the
  // loop is finite whatever the geometry, even if rounding left a face bad at its anchor.
  std::vector<char> touched(static_cast<std::size_t>(n), 0);
  std::vector<Index> bad_list;
  for (Index f = 0; f < F.rows(); ++f) {
    if (bad[static_cast<std::size_t>(f)]) bad_list.push_back(f);
  }
  for (int round = 1; !bad_list.empty(); ++round) {
    std::vector<Index> moved, reproject;
    for (const Index f : bad_list) {
      for (int k = 0; k < 3; ++k) {
        const Index i = F(f, k);
        const auto v = static_cast<std::size_t>(i);
        if (touched[v] || fixed[v]) continue;
        touched[v] = 1;
        moved.push_back(i);
      }
    }
    std::sort(moved.begin(), moved.end());
    bool any_step_changed = false;
    for (const Index i : moved) {
      const auto v = static_cast<std::size_t>(i);
      touched[v] = 0;
      const double new_step = round >= options.max_halvings ? 0.0 : 0.5 * step[v];
      any_step_changed = any_step_changed || new_step != step[v];
      step[v] = new_step;
      shortened[v] = 1;
      X.row(i) = anchor.row(i) + step[v] * displacement.row(i);
      // Back onto the surface, except at step 0: the anchor itself, exactly.
      if (step[v] != 0.0 && options.project_to_input) reproject.push_back(i);
    }
    project_near_vertices(X, reproject, input, F, topology, features);
    std::vector<Index> faces;
    for (const Index i : moved) {
      for (Index k = topology.face_offsets[static_cast<std::size_t>(i)];
           k < topology.face_offsets[static_cast<std::size_t>(i) + 1]; ++k)
        faces.push_back(topology.vertex_faces[static_cast<std::size_t>(k)]);
    }
    std::sort(faces.begin(), faces.end());
    faces.erase(std::unique(faces.begin(), faces.end()), faces.end());
    for (const Index f : faces) bad[static_cast<std::size_t>(f)] = face_badness(criteria, X, f);
    bad_list.clear();
    for (const Index f : faces) {
      if (bad[static_cast<std::size_t>(f)]) bad_list.push_back(f);
    }
    // Bad faces away from the moved vertices cannot exist: they were bad before and so had all
    // their free vertices moved (or all fixed, and then they are at the anchor and not bad).
    if (!any_step_changed) break;
  }
}

// One solve: minimise the energy for positions X (normalised units), frozen curvature of X.
Vertices solve_once(const Vertices& X, const Faces& F, const Topology& topology, FlowSystemSolver& solver,
                    const FlowOptions& options, FlowReport& report) {
  const auto start = Clock::now();
  FlowFrame frame;
  frame.P = X;
  frame.curvature = principal_curvatures(X, F, topology, options.curvature);
  frame.d = robust_radius(frame.curvature, options.d_percentile);
  report.d = frame.d;
  report.seconds_curvature += seconds_since(start);

  const Vertices Y =
      solver.solve(frame, options.weights, report);
  if (!Y.allFinite()) throw std::runtime_error("vertex flow: the solver diverged");
  return Y;
}

}  // namespace

void validate_flow_options(const FlowOptions& o, Index num_vertices) {
  auto require = [](bool ok, const char* what) {
    if (!ok) throw std::invalid_argument(std::string("vertex flow: ") + what);
  };
  const EnergyWeights& w = o.weights;
  require(std::isfinite(w.lambda) && w.lambda > 0, "lambda must be a finite number > 0");
  require(std::isfinite(w.mu) && w.mu >= 0, "mu must be a finite number >= 0");
  require(std::isfinite(w.epsilon) && w.epsilon > 0, "epsilon must be a finite number > 0");
  require(o.d_percentile >= 0 && o.d_percentile <= 100, "d_percentile must be in [0, 100]");
  require(o.iterations >= 1, "iterations must be at least 1");
  require(o.feature_angle >= 0, "feature_angle must be >= 0 degrees (180 or more disables creases)");
  require(o.max_halvings >= 1, "max_halvings must be at least 1");
  require(o.min_quality >= 0 && o.min_quality <= 1, "min_quality must be in [0, 1]");
  require(o.solver_tolerance > 0 && o.solver_tolerance < 1, "solver_tolerance must be in (0, 1)");
  require(o.curvature.smoothing_rounds >= 0, "curvature.smoothing_rounds must be >= 0");
  if (num_vertices < 0) return;
  for (const Index p : o.pinned)
    if (p < 0 || p >= num_vertices)
      throw std::invalid_argument("vertex flow: pinned vertex " + std::to_string(p) + " is out of range [0, " +
                                  std::to_string(num_vertices) + ")");
}

FlowResult vertex_flow(const Vertices& V, const Faces& F, const FlowOptions& options) {
  validate_flow_options(options, static_cast<Index>(V.rows()));
  if (V.rows() == 0 || F.rows() == 0) throw std::invalid_argument("vertex flow: the mesh is empty");
  return vertex_flow(V, F, build_topology(F, static_cast<Index>(V.rows())), options);
}

FlowResult vertex_flow(const Vertices& V, const Faces& F, const Topology& topology, const FlowOptions& options) {
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
        "vertex flow: the bounding box has zero size (all vertices at one point, or coordinates too small to compute with)");
  if (!topology.is_manifold()) throw std::invalid_argument("vertex flow: " + describe_non_manifold(topology));
  FlowResult result;
  FlowReport& report = result.report;

  std::vector<char> fixed(static_cast<std::size_t>(n), 0);
  for (Index i = 0; i < n; ++i) {
    // Isolated vertices have no energy terms but the pull; keep them where they are.
    if ((options.fix_boundary && topology.is_boundary_vertex[static_cast<std::size_t>(i)]) || topology.valence(i) == 0)
      fixed[static_cast<std::size_t>(i)] = 1;
  }
  for (const Index p : options.pinned) fixed[static_cast<std::size_t>(p)] = 1;
  // Sharp features (only with the projection, which is what enforces them): corners stay.
  const SurfaceFeatures features =
      detect_features(V, F, topology, options.project_to_input ? options.feature_angle : 180.0);
  for (Index i = 0; i < n; ++i) {
    if (features.vertex_kind[static_cast<std::size_t>(i)] == SurfaceFeatures::Kind::Corner)
      fixed[static_cast<std::size_t>(i)] = 1;
  }
  report.fixed_vertices = static_cast<Index>(std::count(fixed.begin(), fixed.end(), 1));

  // Normalise: centroid at the origin, mean edge length 1.
  const Eigen::RowVector3d centroid = V.colwise().mean();
  report.mean_edge_length = mean_edge_length(V, topology);
  const double scale = report.mean_edge_length > 0 ? report.mean_edge_length : 1.0;
  const Vertices input = (V.rowwise() - centroid) / scale;

  Vertices X = input;
  // One solver for all rounds: the connectivity is fixed, so its ordering is computed once.
  FlowSystemSolver solver(topology, fixed, options.solver, options.solver_tolerance);
  const GuardCriteria criteria = guard_criteria(input, F, options.min_quality);
  std::vector<char> shortened(static_cast<std::size_t>(n), 0);
  for (int round = 0; round < options.iterations; ++round) {
    const Vertices start_of_round = X;
    X = solve_once(X, F, topology, solver, options, report);
    if (options.project_to_input) {
      const auto start = Clock::now();
      std::vector<Index> free_rows;
      for (Index i = 0; i < n; ++i) {
        if (!fixed[static_cast<std::size_t>(i)]) free_rows.push_back(i);
      }
      project_near_vertices(X, free_rows, input, F, topology, features);
      report.seconds_projection += seconds_since(start);
    }
    // Guarded after every round, not only the last: the next round's curvature is estimated on
    // X, and on the unguarded fandisk after three rounds (671 flipped or degenerate faces) it
    // reached 1e15 per mean edge length, which made the normal matrix numerically indefinite.
    const auto start = Clock::now();
    guard(X, start_of_round, input, criteria, fixed, topology, features, options, shortened, report);
    report.seconds_guard += seconds_since(start);
  }

  report.limited_vertices = static_cast<Index>(std::count(shortened.begin(), shortened.end(), 1));
  report.d *= scale;

  result.V = (X * scale).rowwise() + centroid;
  // Fixed vertices are returned bit for bit.
  for (Index i = 0; i < n; ++i) {
    if (fixed[static_cast<std::size_t>(i)]) result.V.row(i) = V.row(i);
  }
  return result;
}

}  // namespace vertexflow
