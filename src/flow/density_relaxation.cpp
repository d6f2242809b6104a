#include "density_relaxation.h"

#include "numerics/parallel.h"

#include <cmath>

namespace vertexflow {

Eigen::VectorXd sizing_density(const Curvature& curvature, const DensityRelaxation& options) {
  const Index n = static_cast<Index>(curvature.k1.size());
  Eigen::VectorXd density(n);
  for (Index i = 0; i < n; ++i)
    density[i] = std::pow(options.epsilon + std::abs(curvature.k1[i]) + std::abs(curvature.k2[i]), options.exponent);
  return density;
}

Vertices density_pass_proposal(const Vertices& X, const Faces& F, const Topology& topology,
                               const Eigen::VectorXd& density, const std::vector<Index>& rows, double step) {
  Vertices proposal = X;
  parallel_for_index(static_cast<Index>(rows.size()), [&](Index r) {
    const Index i = rows[static_cast<std::size_t>(r)];
    Eigen::Vector3d weighted = Eigen::Vector3d::Zero();
    double total = 0;
    for (Index k = topology.face_offsets[static_cast<std::size_t>(i)];
         k < topology.face_offsets[static_cast<std::size_t>(i) + 1]; ++k) {
      const Index f = topology.vertex_faces[static_cast<std::size_t>(k)];
      const Eigen::Vector3d a = X.row(F(f, 0)), b = X.row(F(f, 1)), c = X.row(F(f, 2));
      const double weight =
          0.5 * (b - a).cross(c - a).norm() * (density[F(f, 0)] + density[F(f, 1)] + density[F(f, 2)]) / 3.0;
      weighted += weight * (a + b + c) / 3.0;
      total += weight;
    }
    // A vertex whose faces all have zero area has no centroid to move to.
    if (total > 0) proposal.row(i) += step * (weighted / total - X.row(i).transpose()).transpose();
  });
  return proposal;
}

}  // namespace vertexflow
