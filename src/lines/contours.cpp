// Occluding contours and suggestive contours (lines.h): the view-dependent lines.
#include "lines/zero_set.h"
#include "numerics/parallel.h"

#include <cmath>

namespace vertexflow {
namespace {

// Unit vector from vertex v towards the viewer.
Eigen::Vector3d to_viewer(const Vertices& V, Index v, const View& view) {
  const Eigen::Vector3d d = view.orthographic ? Eigen::Vector3d(-view.direction) : view.eye - V.row(v).transpose();
  const double length = d.norm();
  return length > 0 ? Eigen::Vector3d(d / length) : Eigen::Vector3d::Zero();
}

}  // namespace

std::vector<Polyline> occluding_contours(const Vertices& V, const Faces& F, const Vertices& normals, const View& view) {
  lines_detail::check_line_input(V, F, {normals.rows()}, "occluding contours");
  Eigen::VectorXd g(V.rows());
  parallel_for_index(V.rows(), [&](Index v) {
    const Eigen::Vector3d normal = normals.row(v).transpose();
    g[v] = view.orthographic ? -normal.dot(view.direction) : normal.dot(view.eye - V.row(v).transpose());
  });
  lines_detail::ZeroSetInput input;
  input.g = &g;
  return lines_detail::zero_set(V, F, input, LineType::Contour);
}

std::vector<Polyline> suggestive_contours(const Vertices& V, const Faces& F, const Curvature& curvature,
                                          const CurvatureDerivative& derivative, const View& view, double threshold) {
  lines_detail::check_line_input(V, F, {curvature.N.rows(), curvature.T1.rows(), derivative.C.rows()},
                                 "suggestive contours");
  const Index n = V.rows();
  // g = k_r sin^2(theta) = II(w, w) with w the unprojected-length tangent part of the unit view
  // vector: the same zeros as k_r, and no division where the surface faces the viewer head-on.
  // keep = tan(theta) D_w k_r - threshold (lines.h), and only where n . v > 0.
  Eigen::VectorXd g(n), keep(n);
  parallel_for_index(n, [&](Index v) {
    const Eigen::Vector3d to = to_viewer(V, v, view);
    const double cos_theta = to.dot(curvature.N.row(v).transpose());
    const double u = to.dot(curvature.T1.row(v).transpose()), w = to.dot(curvature.T2.row(v).transpose());
    const double sin2 = u * u + w * w;
    g[v] = curvature.k1[v] * u * u + curvature.k2[v] * w * w;
    if (!(cos_theta > 0) || !(sin2 > 1e-12)) {
      keep[v] = -threshold - 1;  // back-facing, or seen head-on (w undefined)
      return;
    }
    // sin(theta) D_w k_r = C(w, w, w) / |w|^2 - 2 cos(theta) tau_r^2 (DeCarlo et al. 2004 in
    // curvature.h's signs), tau_r = (k2 - k1) u w / |w|^2; divided by cos(theta).
    const Eigen::Vector2d dir(u, w);
    const double tau = (curvature.k2[v] - curvature.k1[v]) * u * w / sin2;
    const double scaled = derivative.evaluate(v, dir, dir, dir) / sin2 - 2 * cos_theta * tau * tau;
    keep[v] = scaled / cos_theta - threshold;
  });
  lines_detail::ZeroSetInput input;
  input.g = &g;
  input.keep = &keep;
  return lines_detail::zero_set(V, F, input, LineType::SuggestiveContour);
}

}  // namespace vertexflow
