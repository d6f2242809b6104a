#include "vertexflow/statistics.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace vertexflow {

double percentile(std::vector<double> values, double p) {
  if (!(p >= 0 && p <= 100)) throw std::invalid_argument("percentile: " + std::to_string(p) + " is outside [0, 100]");
  if (values.empty()) return 0.0;
  const auto rank = static_cast<std::size_t>(std::ceil(p / 100.0 * static_cast<double>(values.size())));
  const std::size_t index = std::min(values.size() - 1, rank > 0 ? rank - 1 : 0);
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(index), values.end());
  return values[index];
}

}  // namespace vertexflow
