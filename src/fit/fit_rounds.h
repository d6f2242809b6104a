// Internal to the fit stage: the rounds that reference mode and smooth mode share (fit.h): the
// solve of the round's linear system (fit_system.h), then the guard (guard.h).
#pragma once

#include "fit_system.h"
#include "vertexflow/fit.h"
#include "vertexflow/guard.h"
#include "vertexflow/topology.h"

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace vertexflow {

struct GuardCriteria;

/// Throws std::invalid_argument, its message starting with `context`, for an empty mesh, a
/// non-finite coordinate, or options out of range (fit.h's fit_to_reference).
void validate_fit(const Vertices& V, const Faces& F, const FitOptions& options, const std::string& context);

/// The state of a fit's rounds: which vertices are fixed (boundary unless
/// options.constraints.fix_boundary is false, pins, vertices without faces), the system, and the guard.
class FitRounds {
 public:
  FitRounds(const Vertices& V, const Faces& F, const FitOptions& options);
  /// The same with the topology of F already built.
  FitRounds(const Vertices& V, const Faces& F, Topology topology, const FitOptions& options);
  ~FitRounds();
  FitRounds(const FitRounds&) = delete;
  FitRounds& operator=(const FitRounds&) = delete;

  /// One round from X: the solve of fit.h's energy for these data rows (either list may be
  /// empty), then the guard against the positions X. Adds its times to the report.
  Vertices step(const Vertices& X, const std::vector<DataRow>& to_mesh, const std::vector<DataRow>& to_reference,
                FitReport& report);

  /// The result: fixed vertices back to their input coordinates bit for bit, the guard's counts
  /// in the report.
  Vertices finish(Vertices X, FitReport& report) const;

 private:
  const Vertices& V_;
  const Faces& F_;
  const FitOptions& options_;
  Topology topology_;
  std::vector<char> fixed_;
  std::unique_ptr<FitSystem> system_;
  std::unique_ptr<GuardCriteria> criteria_;
  std::vector<char> shortened_;
  GuardCounts guard_counts_;
};

}  // namespace vertexflow
