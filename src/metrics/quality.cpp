#include "vertexflow/quality.h"

#include "vertexflow/statistics.h"

#include "numerics/parallel.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace vertexflow {

double triangle_quality(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, const Eigen::Vector3d& p2) {
  const double a = (p1 - p2).norm(), b = (p2 - p0).norm(), c = (p0 - p1).norm();
  const double denominator = a * b * c;
  const double value = denominator > 0 ? (b + c - a) * (c + a - b) * (a + b - c) / denominator : 0.0;
  return std::clamp(value, 0.0, 1.0);
}

Eigen::VectorXd triangle_quality(const Vertices& V, const Faces& F) {
  Eigen::VectorXd q(F.rows());
  parallel_for_index(
      static_cast<Index>(F.rows()),
      [&](Index f) {
        q[f] = triangle_quality(V.row(F(f, 0)).transpose(), V.row(F(f, 1)).transpose(), V.row(F(f, 2)).transpose());
      },
      4096, 4096);
  return q;
}

QualityStats summarize_quality(const Eigen::VectorXd& quality) {
  QualityStats s;
  const Eigen::Index n = quality.size();
  if (n == 0) return s;
  s.min = quality.minCoeff();
  s.mean = quality.mean();
  std::int64_t below = 0;
  for (Eigen::Index i = 0; i < n; ++i) {
    below += quality[i] < 0.3;
    const auto bin = std::clamp<std::int64_t>(static_cast<std::int64_t>(std::floor(quality[i] * 10)), 0, 9);
    ++s.histogram[static_cast<std::size_t>(bin)];
  }
  s.fraction_below_0_3 = static_cast<double>(below) / static_cast<double>(n);
  s.p5 = percentile(std::vector<double>(quality.data(), quality.data() + n), 5);
  return s;
}

}  // namespace vertexflow
