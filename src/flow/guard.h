// Internal to the flow stage: the guard that keeps the flow's promise (flow.h): no face flips
// or degenerates, and none ends below min(min_quality, its input quality).
#pragma once

#include "vertexflow/features.h"
#include "vertexflow/flow.h"
#include "vertexflow/topology.h"

#include <vector>

namespace vertexflow {

/// What the guard repairs (FlowOptions::min_quality): faces that turned by more than 90
/// degrees, became degenerate, or whose radius ratio fell below their floor (the rule is in
/// FlowOptions::min_quality). Faces already degenerate in `before` cannot be judged (no
/// normal) and are never bad: returning their vertices to the input restores them, so the
/// guard could not repair them.
struct GuardCriteria {
  const Vertices& before;
  const Faces& F;
  double min_area = 0;
  Eigen::VectorXd quality_floor;  ///< per face; a face is bad below it
};

/// The criteria for the input positions `before` (normalised units), with the floors of
/// FlowOptions::min_quality and FlowOptions::sliver_floor.
GuardCriteria guard_criteria(const Vertices& before, const Faces& F, double min_quality, double sliver_floor);

/// Shortens the displacement from `anchor` (the positions before the round, no face bad) of X
/// until no face is bad. Each round halves one corner of every bad face, the one whose halving
/// helps that face most; a shortened vertex is projected back onto the input (when
/// options.project_to_input), and at its max_halvings-th halving it is at its anchor. Then
/// passes offer the vertices left short their whole move again from where they are, until a
/// pass brings fewer than 2% of them to their targets. Counts the bad faces of X in report (summed over rounds) and
/// marks the vertices that end short of their move in X.
void guard(Vertices& X, const Vertices& anchor, const Vertices& input, const GuardCriteria& criteria,
           const std::vector<char>& fixed, const Topology& topology, const SurfaceFeatures& features,
           const FlowOptions& options, std::vector<char>& shortened, FlowReport& report);

}  // namespace vertexflow
