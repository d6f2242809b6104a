#include "flow_setup.h"

#include "numerics/parallel.h"

#include "vertexflow/quality.h"
#include "vertexflow/statistics.h"

#include <Eigen/Eigenvalues>

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

// F_sliver's blocks (flow_energy.h): per corner of each sliver, m m^T / h^2 with m the unit
// in-plane vector across the opposite edge and h the altitude. A face degenerate at X has no
// plane and adds nothing (the guard keeps faces from degenerating).
std::vector<Eigen::Matrix3d> sliver_stiffness(const Vertices& X, const Faces& F, const std::vector<Index>& faces,
                                              Index num_vertices) {
  std::vector<Eigen::Matrix3d> stiffness(static_cast<std::size_t>(num_vertices), Eigen::Matrix3d::Zero());
  for (const Index f : faces) {
    const Eigen::Vector3d p[3] = {X.row(F(f, 0)).transpose(), X.row(F(f, 1)).transpose(), X.row(F(f, 2)).transpose()};
    const Eigen::Vector3d normal = (p[1] - p[0]).cross(p[2] - p[0]);
    const double twice_area = normal.norm();
    if (!(twice_area > 0)) continue;
    for (int c = 0; c < 3; ++c) {
      const Eigen::Vector3d edge = p[(c + 2) % 3] - p[(c + 1) % 3];
      const double length = edge.norm();
      const double altitude = twice_area / length;
      const Eigen::Vector3d across = (normal / twice_area).cross(edge / length);
      stiffness[static_cast<std::size_t>(F(f, c))] += across * across.transpose() / (altitude * altitude);
    }
  }
  return stiffness;
}

}  // namespace

Vertices denormalised(const Vertices& X, const FlowSetup& setup) {
  Vertices out(X.rows(), 3);
  parallel_for_index(static_cast<Index>(X.rows()),
                     [&](Index i) { out.row(i) = (X.row(i) * setup.scale) + setup.centroid; });
  return out;
}

Vertices normalised(const Vertices& V, const FlowSetup& setup) {
  // Row by row on all threads, each the same expression: the result's 24 bytes per vertex are
  // first touched by both (the page faults were most of this copy's 0.6 s at 10M vertices).
  Vertices out(V.rows(), 3);
  parallel_for_index(static_cast<Index>(V.rows()),
                     [&](Index i) { out.row(i) = (V.row(i) - setup.centroid) / setup.scale; });
  return out;
}

FlowSetup prepare_flow(const Vertices& V, const Faces& F, const Topology& topology, const FlowOptions& options) {
  const Index n = static_cast<Index>(V.rows());
  FlowSetup setup;
  std::vector<char>& fixed = setup.fixed;
  fixed.assign(static_cast<std::size_t>(n), 0);
  for (Index i = 0; i < n; ++i) {
    if ((options.constraints.fix_boundary && topology.is_boundary_vertex[static_cast<std::size_t>(i)]) ||
        topology.valence(i) == 0)
      fixed[static_cast<std::size_t>(i)] = 1;
  }
  for (const Index p : options.constraints.pinned) fixed[static_cast<std::size_t>(p)] = 1;
  setup.features = detect_features_without_normals(
      V, F, topology, options.project_to_input ? options.feature_angle : 180.0, options.constraints.crease_edges);
  for (Index i = 0; i < n; ++i) {
    if (setup.features.vertex_kind[static_cast<std::size_t>(i)] == SurfaceFeatures::Kind::Corner)
      fixed[static_cast<std::size_t>(i)] = 1;
  }
  // Centroid at the origin, mean edge length 1.
  // Summed in row order by hand: Eigen's V.colwise().mean() sums the columns that it loads as
  // one packet in another order than the others, and which columns those are follows the
  // destination's address modulo 16, so the bytes of the whole flow changed with the layout of
  // FlowSetup (when SurfaceFeatures changed size, x and z moved by 1e-17).
  for (Index i = 0; i < n; ++i) setup.centroid += V.row(i);
  setup.centroid /= static_cast<double>(n);
  setup.mean_edge_length = mean_edge_length(V, topology);
  setup.scale = setup.mean_edge_length > 0 ? setup.mean_edge_length : 1.0;
  setup.input = normalised(V, setup);
  if (options.guard.min_quality > 0 && options.weights.sliver > 0) {
    const Eigen::VectorXd quality = triangle_quality(setup.input, F);
    for (Index f = 0; f < static_cast<Index>(F.rows()); ++f)
      if (quality[f] < options.guard.min_quality) setup.sliver_faces.push_back(f);
  }
  return setup;
}

void release_during_solve(FlowSetup& setup) {
  Vertices().swap(setup.input);
  Vertices().swap(setup.features.vertex_normals);
}

void restore_after_solve(FlowSetup& setup, const Vertices& V, const Faces& F) {
  if (setup.input.rows() == 0) setup.input = normalised(V, setup);
  // detect_features' own normals (features.h).
  if (setup.features.vertex_normals.rows() == 0) setup.features.vertex_normals = vertex_normals(V, F);
}

FlowFrame flow_frame(const Vertices& X, const Faces& F, const Topology& topology, const FlowOptions& options,
                     const std::vector<Index>& sliver_faces) {
  FlowFrame frame;
  frame.P = copy_rows_in_parallel(X);
  frame.curvature = principal_curvatures(X, F, topology, options.curvature);
  frame.d = robust_radius(frame.curvature, options.d_percentile);
  if (!sliver_faces.empty())
    frame.sliver_stiffness = sliver_stiffness(X, F, sliver_faces, static_cast<Index>(X.rows()));
  return frame;
}

FlowFrame flow_frame_on_reference(const Vertices& X, const Faces& F, const Topology& topology,
                                  const FlowOptions& options, const std::vector<Index>& sliver_faces,
                                  const ReferenceSurface& surface, const std::vector<char>& fixed) {
  FlowFrame frame = flow_frame(X, F, topology, options, sliver_faces);
  const std::vector<ClosestPoint> feet = surface.query.closest_points(X);
  const Faces& FS = surface.query.faces();
  const Curvature& S = surface.curvature;
  Curvature& c = frame.curvature;
  parallel_for_index(X.rows(), [&](Index i) {
    const ClosestPoint& foot = feet[static_cast<std::size_t>(i)];
    if (!fixed[static_cast<std::size_t>(i)]) frame.P.row(i) = foot.point.transpose();
    // The shape operators of the face's corners, blended: sum b_k (k1 T1 T1^T + k2 T2 T2^T)_k.
    Eigen::Matrix3d shape = Eigen::Matrix3d::Zero();
    Eigen::Vector3d normal = Eigen::Vector3d::Zero();
    for (int k = 0; k < 3; ++k) {
      const Index v = FS(foot.face, k);
      const Eigen::Vector3d t1 = S.T1.row(v).transpose(), t2 = S.T2.row(v).transpose();
      shape += foot.barycentric[k] * (S.k1[v] * t1 * t1.transpose() + S.k2[v] * t2 * t2.transpose());
      normal += foot.barycentric[k] * S.N.row(v).transpose();
    }
    if (!(normal.norm() > 0)) return;  // opposite normals cancel: keep X's own frame
    normal.normalize();
    const Eigen::Matrix3d tangent = Eigen::Matrix3d::Identity() - normal * normal.transpose();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(tangent * shape * tangent);
    // Of the three eigenvectors, the one closest to the normal has eigenvalue 0; the others are
    // the principal directions.
    int along = 0;
    for (int k = 1; k < 3; ++k)
      if (std::abs(eigen.eigenvectors().col(k).dot(normal)) > std::abs(eigen.eigenvectors().col(along).dot(normal)))
        along = k;
    const int a = along == 0 ? 1 : 0, b = along == 2 ? 1 : 2;                            // the other two, a < b
    Eigen::Vector3d t1 = eigen.eigenvectors().col(b), t2 = eigen.eigenvectors().col(a);  // ascending values
    if (t1.cross(t2).dot(normal) < 0) t2 = -t2;
    c.k1[i] = eigen.eigenvalues()[b];
    c.k2[i] = eigen.eigenvalues()[a];
    c.T1.row(i) = t1.transpose();
    c.T2.row(i) = t2.transpose();
    c.N.row(i) = normal.transpose();
  });
  frame.d = robust_radius(c, options.d_percentile);
  return frame;
}

}  // namespace vertexflow
