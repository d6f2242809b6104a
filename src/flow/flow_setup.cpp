#include "flow_setup.h"

#include "vertexflow/statistics.h"

#include <algorithm>
#include <cmath>

namespace vertexflow {
namespace {

// The radius d of Eq. 6: 1 / (percentile of the largest |k| per vertex). The paper's literal
// choice is the 100th percentile (FlowOptions::d_percentile).
double robust_radius(const Curvature& c, double at_percentile) {
  std::vector<double> k(static_cast<std::size_t>(c.k1.size()));
  for (Eigen::Index i = 0; i < c.k1.size(); ++i)
    k[static_cast<std::size_t>(i)] = std::max(std::abs(c.k1[i]), std::abs(c.k2[i]));
  const double largest = percentile(std::move(k), at_percentile);
  return largest > 0 ? 1.0 / largest : 1.0;
}

}  // namespace

FlowSetup prepare_flow(const Vertices& V, const Faces& F, const Topology& topology, const FlowOptions& options) {
  const Index n = static_cast<Index>(V.rows());
  FlowSetup setup;
  std::vector<char>& fixed = setup.fixed;
  fixed.assign(static_cast<std::size_t>(n), 0);
  for (Index i = 0; i < n; ++i) {
    if ((options.fix_boundary && topology.is_boundary_vertex[static_cast<std::size_t>(i)]) || topology.valence(i) == 0)
      fixed[static_cast<std::size_t>(i)] = 1;
  }
  for (const Index p : options.pinned) fixed[static_cast<std::size_t>(p)] = 1;
  setup.features = detect_features(V, F, topology, options.project_to_input ? options.feature_angle : 180.0);
  for (Index i = 0; i < n; ++i) {
    if (setup.features.vertex_kind[static_cast<std::size_t>(i)] == SurfaceFeatures::Kind::Corner)
      fixed[static_cast<std::size_t>(i)] = 1;
  }
  // Centroid at the origin, mean edge length 1.
  setup.centroid = V.colwise().mean();
  setup.mean_edge_length = mean_edge_length(V, topology);
  setup.scale = setup.mean_edge_length > 0 ? setup.mean_edge_length : 1.0;
  setup.input = (V.rowwise() - setup.centroid) / setup.scale;
  return setup;
}

FlowFrame flow_frame(const Vertices& X, const Faces& F, const Topology& topology, const FlowOptions& options) {
  FlowFrame frame;
  frame.P = X;
  frame.curvature = principal_curvatures(X, F, topology, options.curvature);
  frame.d = robust_radius(frame.curvature, options.d_percentile);
  return frame;
}

}  // namespace vertexflow
