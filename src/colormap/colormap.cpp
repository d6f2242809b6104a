#include "vertexflow/colormap.h"

#include "vertexflow/statistics.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace vertexflow {

double robust_color_limit(const Eigen::VectorXd& values) {
  if (values.size() == 0) return 1.0;
  const std::vector<double> sample(values.data(), values.data() + values.size());
  double limit = std::max(std::abs(percentile(sample, 5)), std::abs(percentile(sample, 95)));
  if (!(limit > 0)) limit = values.cwiseAbs().maxCoeff();
  return limit > 0 && std::isfinite(limit) ? limit : 1.0;
}

Colors diverging_colors(const Eigen::VectorXd& values, double limit) {
  const Eigen::Vector3d blue(59, 76, 192), white(221, 221, 221), red(180, 4, 38);
  Colors colors(values.size(), 3);
  for (Eigen::Index i = 0; i < values.size(); ++i) {
    const double t = std::isfinite(values[i]) ? std::clamp(values[i] / limit, -1.0, 1.0) : 0.0;
    const Eigen::Vector3d c = t >= 0 ? Eigen::Vector3d(white + t * (red - white)) : Eigen::Vector3d(white - t * (blue - white));
    for (int k = 0; k < 3; ++k) colors(i, k) = static_cast<std::uint8_t>(std::lround(c[k]));
  }
  return colors;
}

}  // namespace vertexflow
