// Internal to the flow stage: minimising the energy of flow_energy.h for one frame, by solving
// its normal equations H d = b (flow_terms.h) for the displacement d = V - P from the frame's
// positions, rows and columns of the fixed vertices removed (their d is 0), with the method
// that LinearSolver chooses (flow.h; flow_solver.cpp has the policy and its calibration).
#pragma once

#include "flow_terms.h"
#include "numerics/multigrid.h"
#include "vertexflow/flow.h"
#include "vertexflow/flow_energy.h"

#include <memory>
#include <string>
#include <vector>

namespace vertexflow {

/// Solves the flow's system for one connectivity and one set of fixed vertices. Keeps what
/// depends only on them between solves (options.iterations > 1): the fill-reducing ordering
/// and CHOLMOD's symbolic factorisation.
class FlowSystemSolver {
 public:
  /// `fixed` marks the vertices held at frame.P; `kind` and `tolerance` as in FlowOptions.
  FlowSystemSolver(const Topology& topology, std::vector<char> fixed, LinearSolver kind = LinearSolver::Automatic,
                   double tolerance = FlowOptions{}.solver_tolerance);
  ~FlowSystemSolver();
  FlowSystemSolver(const FlowSystemSolver&) = delete;
  FlowSystemSolver& operator=(const FlowSystemSolver&) = delete;

  /// Minimises the flow energy of `frame` (normalised units); returns all positions. Adds its
  /// times to report.seconds_assembly, seconds_factorization and seconds_solve, and sets
  /// report.solver_error, solver_used and solver_iterations. Throws std::runtime_error if the
  /// factorisation fails.
  Vertices solve(const FlowFrame& frame, const EnergyWeights& weights, FlowReport& report);
  /// The same, releasing the frame's curvature and sliver blocks once the system is assembled
  /// (168 bytes per vertex that the solve, the flow's longest phase, does not need); the
  /// frame's P and d stay.
  Vertices solve_releasing(FlowFrame& frame, const EnergyWeights& weights, FlowReport& report);

  /// The phase name under which the iterations report their progress (progress.h): the fall of
  /// the relative residual towards the tolerance, on a log scale, every few iterations. The
  /// caller places the solve's part (ProgressPart); the default is "solve".
  void set_progress_phase(std::string phase);

  /// The vertices in the order the solve numbers them (breadth first from a space-filling order:
  /// neighbours close together), or empty before the first solve.
  [[nodiscard]] const std::vector<Index>& vertex_order() const;

 private:
  Vertices solve(const FlowFrame& frame, FlowFrame* release, const EnergyWeights& weights, FlowReport& report);
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// The inverses of H's diagonal blocks for `terms` (zero at fixed vertices): block-Jacobi, which
/// captures each vertex's anisotropy (stiff along the normal, soft in the tangent plane)
/// exactly; the preconditioner of every iterative path.
std::vector<InverseFactor3f> block_jacobi(const FlowTerms& terms);

/// The prolongators of the multilevel path's hierarchy (multigrid.h) for the system of `terms`:
/// Smoothed where a connected region of at least 600 free vertices is planar at the mesh's own
/// scale (|k1| + |k2| below 0.1 / sqrt(n) per mean edge length, n vertices), else Tentative
/// (flow_solver.cpp has the measurements). Invariant under rigid motion, uniform scale and
/// renumbering, as the normalised terms are.
AdditiveMultilevel::Prolongators multilevel_prolongators(const FlowTerms& terms);

/// One solve with a temporary FlowSystemSolver.
Vertices solve_flow_system(const Topology& topology, const FlowFrame& frame, const EnergyWeights& weights,
                           const std::vector<char>& fixed, FlowReport& report);

}  // namespace vertexflow
