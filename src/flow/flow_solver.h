// Internal to the flow stage: solving the least-squares system of flow_energy.h. Kept apart
// from flow.cpp (normalisation, curvature, guard) because it is the part whose algorithm
// depends on the mesh size.
//
// Both solvers work on the displacement d = V - P from the input and on the normal equations
// H d = b with H = A^T A (flow_energy.h's rows), b = A^T (rhs) - H P, rows and columns of the
// fixed vertices removed (their d is 0). H is never formed by a sparse-sparse product: its
// terms are products of per-vertex 3x3 blocks over one-rings (flow_solver.cpp).
#pragma once

#include "vertexflow/flow.h"
#include "vertexflow/flow_energy.h"

#include <memory>
#include <vector>

namespace vertexflow {

/// Solves the flow's system for one connectivity and one set of fixed vertices. Keeps what
/// depends only on them between solves (options.iterations > 1): the fill-reducing ordering
/// and CHOLMOD's symbolic factorisation.
class FlowSystemSolver {
 public:
  /// `fixed` marks the vertices held at frame.P; `kind` and `tolerance` as in FlowOptions.
  FlowSystemSolver(const Topology& topology, std::vector<char> fixed, LinearSolver kind = LinearSolver::Automatic,
                   double tolerance = 1e-7);
  ~FlowSystemSolver();
  FlowSystemSolver(const FlowSystemSolver&) = delete;
  FlowSystemSolver& operator=(const FlowSystemSolver&) = delete;

  /// Minimises the flow energy of `frame` (normalised units); returns all positions. Adds its
  /// times to report.seconds_assembly, seconds_factorization and seconds_solve, and sets
  /// report.solver_error, solver_used and solver_iterations. Throws std::runtime_error if the
  /// factorisation fails.
  Vertices solve(const FlowFrame& frame, const EnergyWeights& weights, FlowReport& report);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// One solve with a temporary FlowSystemSolver.
Vertices solve_flow_system(const Topology& topology, const FlowFrame& frame, const EnergyWeights& weights,
                           const std::vector<char>& fixed, FlowReport& report);

}  // namespace vertexflow
