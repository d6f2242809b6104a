// Internal to the flow stage: what vertex_flow prepares before its solves (the fixed vertices,
// the features, the normalised copy) and the frozen data of each solve (the frame). Tests set
// up the solver's problems through these, so that they test the problem the flow solves.
#pragma once

#include "vertexflow/curvature.h"
#include "vertexflow/distance.h"
#include "vertexflow/features.h"
#include "vertexflow/flow.h"
#include "vertexflow/flow_energy.h"
#include "vertexflow/topology.h"

#include <vector>

namespace vertexflow {

struct FlowSetup {
  /// Held at the input: boundary vertices (when options.constraints.fix_boundary), isolated vertices (no
  /// energy terms but the pull), pinned vertices and the corners of the features.
  std::vector<char> fixed;
  /// Sharp features for options.feature_angle, or none without the projection (which is what
  /// enforces them). Their vertex_normals stay empty until restore_after_solve: the solve, the
  /// flow's peak, would free them anyway, and only the projection reads them.
  SurfaceFeatures features;
  /// The normalisation (flow.h, "Scale and rigid motion"): input = (V - centroid) / scale, with
  /// scale the mean edge length (1 if that is 0).
  Eigen::RowVector3d centroid = Eigen::RowVector3d::Zero();
  double scale = 1;
  double mean_edge_length = 0;
  Vertices input;
  /// The faces whose input quality is below options.guard.min_quality (flow_energy.h, F_sliver);
  /// empty when min_quality or weights.sliver is 0.
  std::vector<Index> sliver_faces;
};

/// The preparation of vertex_flow for valid options and a valid mesh.
FlowSetup prepare_flow(const Vertices& V, const Faces& F, const Topology& topology, const FlowOptions& options);

/// Points in the flow's normalised units (flow.h, "Scale and rigid motion"): (V - centroid) /
/// scale. With denormalised, the result's way back (X scale + centroid), the one place the
/// normalisation is written, so that restoring the input gives its bytes and the reference is
/// normalised as the input is. Both write their rows on all threads (the same bytes).
Vertices normalised(const Vertices& V, const FlowSetup& setup);
Vertices denormalised(const Vertices& X, const FlowSetup& setup);

/// detect_features without the vertex normals (empty): what prepare_flow needs.
SurfaceFeatures detect_features_without_normals(const Vertices& V, const Faces& F, const Topology& topology,
                                                double angle_degrees,
                                                const std::vector<std::array<Index, 2>>& crease_edges = {});

/// Frees what a solve does not read of `setup` (the normalised input and the features' vertex
/// normals: 48 bytes per vertex at the solve, the flow's peak); restore_after_solve(setup, V, F)
/// with prepare_flow's V and F computes what is missing of them, bit for bit (the normals
/// detect_features would have computed). Call it before any projection.
void release_during_solve(FlowSetup& setup);
void restore_after_solve(FlowSetup& setup, const Vertices& V, const Faces& F);

/// The frame of one solve at positions X (normalised units): X, its curvature
/// (options.curvature), the radius d of Eq. 6 at options.d_percentile and F_sliver's
/// stiffness at X for `sliver_faces` (none if empty).
FlowFrame flow_frame(const Vertices& X, const Faces& F, const Topology& topology, const FlowOptions& options,
                     const std::vector<Index>& sliver_faces = {});

/// The true surface S of vertex_flow_on_reference, in the flow's normalised units: its
/// closest-point queries and its own curvature.
struct ReferenceSurface {
  DistanceQuery query;
  Curvature curvature;
};

/// The frame of flow_frame with the anchors P and the curvature (k1, k2, T1, T2, N) taken from S
/// at the foot points of X (flow.h, vertex_flow_on_reference); the areas and d from X's and
/// S's curvature as flow_frame. A `fixed` vertex keeps its anchor at X: the solver returns
/// fixed vertices at their anchors, and one moved onto S would be judged there by the guard,
/// then put back, unguarded, at the end.
FlowFrame flow_frame_on_reference(const Vertices& X, const Faces& F, const Topology& topology,
                                  const FlowOptions& options, const std::vector<Index>& sliver_faces,
                                  const ReferenceSurface& surface, const std::vector<char>& fixed);

}  // namespace vertexflow
