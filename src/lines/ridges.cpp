// Ridges and valleys (lines.h): zeros of the derivative of a principal curvature along its own
// direction, Ohtake, Belyaev and Seidel 2004, with the per-face extremum test of rtsc.
#include "lines/zero_set.h"
#include "numerics/parallel.h"

#include <algorithm>
#include <cmath>

namespace vertexflow {
namespace {

// The lines of one principal curvature. `ridge`: k1 along T1 (C111), maxima, k1 > |k2|;
// otherwise k2 along T2 (C222), minima, k2 < -|k1|. In both cases the curvature is mirrored
// to s k (s = +1 for ridges, -1 for valleys) so the tests read the same.
std::vector<Polyline> principal_extrema(const Vertices& V, const Faces& F, const Curvature& curvature,
                                        const CurvatureDerivative& derivative, double threshold, bool ridge) {
  const Index n = V.rows();
  const double s = ridge ? 1.0 : -1.0;
  const Eigen::VectorXd& k = ridge ? curvature.k1 : curvature.k2;
  const Eigen::VectorXd& other = ridge ? curvature.k2 : curvature.k1;
  const Vertices& T = ridge ? curvature.T1 : curvature.T2;
  Eigen::VectorXd g(n), keep(n);
  parallel_for_index(n, [&](Index v) {
    g[v] = s * derivative.C(v, ridge ? 0 : 3);  // s D_T k: its zeros, and its sign along s T
    keep[v] = std::min(s * k[v] - threshold, s * k[v] - std::abs(other[v]));
  });
  lines_detail::ZeroSetInput input;
  input.g = &g;
  input.keep = &keep;
  // D_T k changes sign with T, and T has no sign: compare across an edge with T aligned.
  input.align = [&](Index a, Index b) { return T.row(a).dot(T.row(b)) < 0 ? -1.0 : 1.0; };
  // An extremum of s k along T: s D_T k decreases along T (T aligned to the first corner's).
  input.face_test = [&](Index f, double g0, double g1, double g2) {
    const Eigen::Vector3d p0 = V.row(F(f, 0)).transpose(), p1 = V.row(F(f, 1)).transpose(),
                          p2 = V.row(F(f, 2)).transpose();
    const Eigen::Vector3d normal = (p1 - p0).cross(p2 - p0);
    // The gradient of the linear interpolant times |normal|^2 (only its sign is used).
    const Eigen::Vector3d gradient = normal.cross((g1 - g0) * (p0 - p2) + (g2 - g0) * (p1 - p0));
    Eigen::Vector3d direction = T.row(F(f, 0)).transpose();
    for (int c = 1; c < 3; ++c) direction += input.align(F(f, 0), F(f, c)) * T.row(F(f, c)).transpose();
    return gradient.dot(direction) < 0;
  };
  return lines_detail::zero_set(V, F, input, ridge ? LineType::Ridge : LineType::Valley);
}

}  // namespace

std::vector<Polyline> ridges_and_valleys(const Vertices& V, const Faces& F, const Curvature& curvature,
                                         const CurvatureDerivative& derivative, double threshold, bool ridges,
                                         bool valleys) {
  lines_detail::check_line_input(V, F, {curvature.T1.rows(), curvature.T2.rows(), derivative.C.rows()},
                                 "ridges and valleys");
  std::vector<Polyline> lines;
  if (ridges) lines = principal_extrema(V, F, curvature, derivative, threshold, true);
  if (valleys) {
    std::vector<Polyline> more = principal_extrema(V, F, curvature, derivative, threshold, false);
    lines.insert(lines.end(), std::make_move_iterator(more.begin()), std::make_move_iterator(more.end()));
  }
  return lines;
}

}  // namespace vertexflow
