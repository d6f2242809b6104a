// Internal to the methods that move vertices (the flow, the fit; guard.h in include/ has the
// options): the guard that keeps their promise, no face flips or degenerates and none ends below
// its quality floor (GuardOptions). Knows nothing of the flow: a method that keeps its vertices
// on a surface passes the projection that puts shortened vertices back on it.
#pragma once

#include "vertexflow/guard.h"
#include "vertexflow/topology.h"

#include <functional>
#include <vector>

namespace vertexflow {

/// What the guard repairs (GuardOptions): faces that turned by more than 90 degrees, became
/// degenerate, or whose radius ratio fell below their floor. Faces already degenerate in
/// `before` cannot be judged (no normal) and are never bad: returning their vertices to the
/// input restores them, so the guard could not repair them.
struct GuardCriteria {
  const Vertices& before;
  const Faces& F;
  double min_area = 0;
  Eigen::VectorXd quality_floor;  ///< per face; a face is bad below it
};

/// The criteria for the input positions `before`, with the floors of GuardOptions.
GuardCriteria guard_criteria(const Vertices& before, const Faces& F, const GuardOptions& options);

/// Moves the rows `rows` of X back onto the method's surface (the flow: the input's, features
/// respected); empty for a method that leaves the surface on purpose (the fit).
using Reprojection = std::function<void(Vertices& X, const std::vector<Index>& rows)>;

/// Shortens the displacement from `anchor` (the positions before the round, no face bad) of X
/// until no face is bad. Each round halves one corner of every bad face, the one whose halving
/// helps that face most; a shortened vertex is reprojected (when `reproject` is set), and at its
/// max_halvings-th halving it is at its anchor. Then passes offer the vertices left short their
/// whole move again from where they are, until a pass brings fewer than 2% of them to their
/// targets. Returns the bad faces of X before any repair, and marks the vertices that end short
/// of their move in `shortened`.
GuardCounts guard(Vertices& X, const Vertices& anchor, const GuardCriteria& criteria, const std::vector<char>& fixed,
                  const Topology& topology, const GuardOptions& options, const Reprojection& reproject,
                  std::vector<char>& shortened);

}  // namespace vertexflow
