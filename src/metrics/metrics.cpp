#include "vertexflow/metrics.h"

#include "numerics/parallel.h"

#include <tbb/parallel_sort.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

namespace vertexflow {
namespace {

// Ranks 1..n, ties sharing their average rank. The pairs (value, index) sorted in parallel:
// the order a stable sort by value gives (a serial one took 4 s of 10M vertices' 9 s of rho).
Eigen::VectorXd ranks(const Eigen::VectorXd& x) {
  const Eigen::Index n = x.size();
  std::vector<std::pair<double, Eigen::Index>> order(static_cast<std::size_t>(n));
  for (Eigen::Index i = 0; i < n; ++i) order[static_cast<std::size_t>(i)] = {x[i], i};
  tbb::parallel_sort(order.begin(), order.end());
  Eigen::VectorXd r(n);
  for (Eigen::Index i = 0; i < n;) {
    Eigen::Index j = i;
    while (j + 1 < n && order[static_cast<std::size_t>(j + 1)].first == order[static_cast<std::size_t>(i)].first) ++j;
    const double average = 0.5 * static_cast<double>(i + j) + 1.0;
    for (Eigen::Index k = i; k <= j; ++k) r[order[static_cast<std::size_t>(k)].second] = average;
    i = j + 1;
  }
  return r;
}

}  // namespace

double spearman_correlation(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  if (a.size() != b.size() || a.size() < 2) return 0.0;
  const Eigen::VectorXd ra = ranks(a).array() - (static_cast<double>(a.size()) + 1) / 2;
  const Eigen::VectorXd rb = ranks(b).array() - (static_cast<double>(b.size()) + 1) / 2;
  const double denominator = std::sqrt(ra.squaredNorm() * rb.squaredNorm());
  return denominator > 0 ? ra.dot(rb) / denominator : 0.0;
}

Eigen::VectorXd vertex_density(const Vertices& V, const Faces& F) {
  // The faces' thirds in parallel, added in face order (the rounding of one loop).
  Eigen::VectorXd third(F.rows());
  parallel_for_index(
      static_cast<Index>(F.rows()), [&](Index f) { third[f] = face_area(V, F, f) / 3.0; }, 4096);
  Eigen::VectorXd area = Eigen::VectorXd::Zero(V.rows());
  for (Index f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) area[F(f, k)] += third[f];
  return area.unaryExpr([](double a) { return a > 0 ? 1.0 / a : 0.0; });
}

double redistribution_rho(const Eigen::VectorXd& surface_curvature, const Vertices& V, const Faces& F) {
  return spearman_correlation(surface_curvature, vertex_density(V, F));
}

EdgeErrorStats edge_error_stats(const Vertices& V, const Topology& topology, const Curvature& surface) {
  std::vector<Eigen::Matrix3d> tensors(static_cast<std::size_t>(surface.k1.size()));
  parallel_for_index(static_cast<Index>(surface.k1.size()),
                     [&](Index i) { tensors[static_cast<std::size_t>(i)] = surface.absolute_tensor(i); });
  return edge_error_stats(V, topology, tensors);
}

EdgeErrorStats edge_error_stats(const Vertices& V, const Topology& topology,
                                const std::vector<Eigen::Matrix3d>& surface_tensors) {
  if (surface_tensors.size() != static_cast<std::size_t>(V.rows()))
    throw std::invalid_argument("edge_error_stats: " + std::to_string(surface_tensors.size()) + " tensors for " +
                                std::to_string(V.rows()) + " vertices");
  EdgeErrorStats stats;
  const Index ne = topology.num_edges();
  if (ne == 0) return stats;
  // The edges' errors in parallel; the sums below are Eigen's, over the whole vector.
  Eigen::VectorXd delta(ne);
  parallel_for_index(ne, [&](Index e) {
    const Index i = topology.edges(e, 0), j = topology.edges(e, 1);
    const Eigen::Vector3d d = (V.row(j) - V.row(i)).transpose();
    // Eq. 2-4 (f_em = the mean of both endpoints' quadratic forms), divided by 8 (docs/metrics.md).
    const double f_em = 0.5 * (d.dot(surface_tensors[static_cast<std::size_t>(i)] * d) +
                               d.dot(surface_tensors[static_cast<std::size_t>(j)] * d));
    delta[e] = f_em / 8.0;
  });
  stats.mean = delta.mean();
  if (stats.mean > 0) {
    stats.max_over_mean = delta.maxCoeff() / stats.mean;
    stats.coefficient_of_variation = std::sqrt((delta.array() - stats.mean).square().mean()) / stats.mean;
  }
  return stats;
}

}  // namespace vertexflow
