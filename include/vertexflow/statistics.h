// Small statistics shared by the metrics, colour maps and the flow.
#pragma once

#include <vector>

namespace vertexflow {

/// Nearest-rank percentile: the value at rank ceil(p / 100 * n) (1-based) of the sorted sample,
/// so p = 0 gives the minimum and p = 100 the maximum; 0 for an empty sample. Throws
/// std::invalid_argument unless 0 <= p <= 100.
double percentile(std::vector<double> values, double p);

/// percentile(values, p) for each p of `ps`, from one copy of the values (each later rank is
/// selected among the values above the one before). Throws as percentile does.
std::vector<double> percentiles(std::vector<double> values, const std::vector<double>& ps);

}  // namespace vertexflow
