// Internal to the flow stage: assembling and solving the least-squares system of
// flow_energy.h. Kept apart from flow.cpp (normalisation, curvature, guard) because it is the
// part whose algorithm depends on the mesh size.
#pragma once

#include "vertexflow/flow.h"
#include "vertexflow/flow_energy.h"

#include <vector>

namespace vertexflow {

/// Minimises the flow energy of `frame` (normalised units) with the vertices marked in `fixed`
/// held at frame.P; returns all positions. Adds its times to report.seconds_assembly and
/// report.seconds_solve and sets report.solver_error. Throws std::runtime_error if the solver
/// fails.
Vertices solve_flow_system(const Topology& topology, const FlowFrame& frame, const EnergyWeights& weights,
                           const std::vector<char>& fixed, FlowReport& report);

}  // namespace vertexflow
