#include "vertexflow/statistics.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

namespace vertexflow {

namespace {

// The 0-based index of the nearest rank of p in n > 0 values.
std::size_t nearest_rank_index(double p, std::size_t n) {
  if (!(p >= 0 && p <= 100)) throw std::invalid_argument("percentile: " + std::to_string(p) + " is outside [0, 100]");
  const auto rank = static_cast<std::size_t>(std::ceil(p / 100.0 * static_cast<double>(n)));
  return std::min(n - 1, rank > 0 ? rank - 1 : 0);
}

}  // namespace

double percentile(std::vector<double> values, double p) {
  if (values.empty()) {
    nearest_rank_index(p, 1);  // checks p
    return 0.0;
  }
  const std::size_t index = nearest_rank_index(p, values.size());
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(index), values.end());
  return values[index];
}

std::vector<double> percentiles(std::vector<double> values, const std::vector<double>& ps) {
  std::vector<std::pair<std::size_t, std::size_t>> wanted;  // (index, slot of ps)
  for (std::size_t k = 0; k < ps.size(); ++k)
    wanted.emplace_back(nearest_rank_index(ps[k], std::max<std::size_t>(values.size(), 1)), k);
  std::vector<double> out(ps.size(), 0.0);
  if (values.empty()) return out;
  std::sort(wanted.begin(), wanted.end());
  // After selecting index i, the values above i are exactly those of the ranks after it.
  std::size_t from = 0;
  for (const auto& [index, slot] : wanted) {
    if (index >= from) {
      std::nth_element(values.begin() + static_cast<std::ptrdiff_t>(from),
                       values.begin() + static_cast<std::ptrdiff_t>(index), values.end());
      from = index + 1;
    }
    out[slot] = values[index];
  }
  return out;
}

}  // namespace vertexflow
