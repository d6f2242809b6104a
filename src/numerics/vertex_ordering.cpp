#include "numerics/vertex_ordering.h"

#include "numerics/parallel.h"

#include <tbb/parallel_sort.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>

namespace vertexflow {

std::vector<Index> space_filling_order(const Vertices& P) {
  const Index n = static_cast<Index>(P.rows());
  std::vector<std::pair<std::uint64_t, Index>> keys(static_cast<std::size_t>(n));
  if (n == 0) return {};
  const Eigen::RowVector3d low = P.colwise().minCoeff(), high = P.colwise().maxCoeff();
  const double extent = std::max((high - low).maxCoeff(), 1e-300);
  parallel_for_index(n, [&](Index i) {
    std::uint64_t code = 0;
    for (int c = 0; c < 3; ++c) {
      const double unit = (P(i, c) - low[c]) / extent;
      // A non-finite coordinate goes to cell 0: its place is arbitrary but fixed (a NaN cast to
      // an integer would be undefined).
      const double cell = std::isfinite(unit) ? std::clamp(unit, 0.0, 1.0) * 2097151.0 : 0.0;
      code |= morton_spread_21(static_cast<std::uint64_t>(cell)) << c;
    }
    keys[static_cast<std::size_t>(i)] = {code, i};
  });
  tbb::parallel_sort(keys.begin(), keys.end());  // keys are unique, so the order is too
  std::vector<Index> order(static_cast<std::size_t>(n));
  for (std::size_t k = 0; k < keys.size(); ++k) order[k] = keys[k].second;
  return order;
}

std::vector<Index> breadth_first_order(const Topology& topology, const std::vector<Index>& seed_order) {
  const auto n = seed_order.size();
  std::vector<Index> order;
  order.reserve(n);
  std::vector<char> seen(n, 0);
  for (const Index seed : seed_order) {
    if (seen[static_cast<std::size_t>(seed)]) continue;
    seen[static_cast<std::size_t>(seed)] = 1;
    std::size_t head = order.size();
    order.push_back(seed);
    while (head < order.size()) {
      const auto [begin, end] = topology.ring(order[head++]);
      for (const Index* j = begin; j != end; ++j) {
        if (seen[static_cast<std::size_t>(*j)]) continue;
        seen[static_cast<std::size_t>(*j)] = 1;
        order.push_back(*j);
      }
    }
  }
  return order;
}

}  // namespace vertexflow
