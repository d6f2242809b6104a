// The fit's rounds (fit_rounds.h).
#include "fit_rounds.h"

#include "../guard/guard.h"
#include "vertexflow/timing.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>

namespace vertexflow {

void validate_fit(const Vertices& V, const Faces& F, const FitOptions& o, const std::string& context) {
  if (V.rows() == 0 || F.rows() == 0) throw std::invalid_argument(context + ": the mesh is empty");
  if (!V.allFinite()) throw std::invalid_argument(context + ": a coordinate is not finite");
  validate_fit_options(o, V.rows(), context.c_str());
}

void validate_fit_options(const FitOptions& o, Index num_vertices, const char* what) {
  auto require = [what](bool ok, const std::string& problem) {
    if (!ok) throw std::invalid_argument(std::string(what) + ": " + problem);
  };
  require(std::isfinite(o.samples_per_vertex) && o.samples_per_vertex > 0, "samples_per_vertex must be > 0");
  require(std::isfinite(o.mesh_to_reference_weight) && o.mesh_to_reference_weight >= 0,
          "mesh_to_reference_weight must be a finite number >= 0");
  require(std::isfinite(o.fairness) && o.fairness >= 0, "fairness must be a finite number >= 0");
  require(std::isfinite(o.proximity) && o.proximity > 0, "proximity must be a finite number > 0");
  require(o.max_rounds >= 1, "max_rounds must be at least 1");
  require(o.max_solver_iterations >= 1, "max_solver_iterations must be at least 1");
  require(std::isfinite(o.tolerance) && o.tolerance >= 0, "tolerance must be a finite number >= 0");
  validate_guard_options(o.guard, what);
  validate_vertex_constraints(o.constraints, num_vertices, what);
}

FitRounds::FitRounds(const Vertices& V, const Faces& F, const FitOptions& options)
    : FitRounds(V, F, build_topology(F, V.rows()), options) {}

FitRounds::FitRounds(const Vertices& V, const Faces& F, Topology topology, const FitOptions& options)
    : V_(V), F_(F), options_(options), topology_(std::move(topology)) {
  const Index n = V.rows();
  fixed_.assign(static_cast<std::size_t>(n), 0);
  for (Index i = 0; i < n; ++i) {
    const auto v = static_cast<std::size_t>(i);
    // Vertices without faces have no data and no ring: nothing decides where they go.
    fixed_[v] = (options.constraints.fix_boundary && topology_.is_boundary_vertex[v]) ||
                topology_.face_offsets[v] == topology_.face_offsets[v + 1];
  }
  for (const Index p : options.constraints.pinned) fixed_[static_cast<std::size_t>(p)] = 1;
  system_ = make_fit_system(F, topology_, fixed_, options);
  criteria_ = std::make_unique<GuardCriteria>(guard_criteria(V, F, options.guard));
  shortened_.assign(static_cast<std::size_t>(n), 0);
}

FitRounds::~FitRounds() = default;

Vertices FitRounds::step(const Vertices& X, const std::vector<DataRow>& to_mesh,
                         const std::vector<DataRow>& to_reference, FitReport& report) {
  auto start = Clock::now();
  Vertices Y = system_->solve(X, to_mesh, to_reference, options_, report);
  report.seconds_solve += seconds_since(start);
  start = Clock::now();
  // No reprojection: the fit leaves the input on purpose.
  const GuardCounts counts = guard(Y, X, *criteria_, fixed_, topology_, options_.guard, {}, shortened_);
  guard_counts_.flipped_before_guard += counts.flipped_before_guard;
  guard_counts_.low_quality_before_guard += counts.low_quality_before_guard;
  report.seconds_guard += seconds_since(start);
  return Y;
}

Vertices FitRounds::finish(Vertices X, FitReport& report) const {
  report.flipped_before_guard = guard_counts_.flipped_before_guard;
  report.low_quality_before_guard = guard_counts_.low_quality_before_guard;
  report.limited_vertices = static_cast<Index>(std::count(shortened_.begin(), shortened_.end(), 1));
  for (Index i = 0; i < X.rows(); ++i) {
    if (fixed_[static_cast<std::size_t>(i)]) X.row(i) = V_.row(i);
  }
  return X;
}

}  // namespace vertexflow
