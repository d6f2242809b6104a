// Internal to the flow stage: the guard that keeps the flow's promise (flow.h): no face flips
// or degenerates, and none ends below min(min_quality, its input quality).
#pragma once

#include "vertexflow/features.h"
#include "vertexflow/flow.h"
#include "vertexflow/topology.h"

#include <vector>

namespace vertexflow {

/// What the guard repairs (FlowOptions::min_quality): faces that turned by more than 90
/// degrees, became degenerate, or whose radius ratio fell below min(min_quality, their
/// input's). Faces already degenerate in `before` cannot be judged (no normal) and are never
/// bad: returning their vertices to the input restores them, so the guard could not repair
/// them.
struct GuardCriteria {
  const Vertices& before;
  const Faces& F;
  double min_area = 0;
  Eigen::VectorXd quality_floor;  ///< per face; a face is bad below it
};

/// The criteria for the input positions `before` (normalised units).
GuardCriteria guard_criteria(const Vertices& before, const Faces& F, double min_quality);

/// Halves the displacement from `anchor` (the positions before the round, not bad) of every
/// vertex of a bad face until no face is bad; a shortened vertex is projected back onto the
/// input (when options.project_to_input), and after max_halvings halvings it is at its anchor.
/// Counts the bad faces in report (summed over rounds) and marks the vertices it shortened.
void guard(Vertices& X, const Vertices& anchor, const Vertices& input, const GuardCriteria& criteria,
           const std::vector<char>& fixed, const Topology& topology, const SurfaceFeatures& features,
           const FlowOptions& options, std::vector<char>& shortened, FlowReport& report);

}  // namespace vertexflow
