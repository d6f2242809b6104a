#include "vertexflow/metrics.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>
#include <vector>

namespace vertexflow {
namespace {

// Ranks 1..n, ties sharing their average rank.
Eigen::VectorXd ranks(const Eigen::VectorXd& x) {
  const Eigen::Index n = x.size();
  std::vector<Eigen::Index> order(static_cast<std::size_t>(n));
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](Eigen::Index a, Eigen::Index b) { return x[a] < x[b]; });
  Eigen::VectorXd r(n);
  for (Eigen::Index i = 0; i < n;) {
    Eigen::Index j = i;
    while (j + 1 < n && x[order[static_cast<std::size_t>(j + 1)]] == x[order[static_cast<std::size_t>(i)]]) ++j;
    const double average = 0.5 * static_cast<double>(i + j) + 1.0;
    for (Eigen::Index k = i; k <= j; ++k) r[order[static_cast<std::size_t>(k)]] = average;
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
  Eigen::VectorXd area = Eigen::VectorXd::Zero(V.rows());
  for (Index f = 0; f < F.rows(); ++f) {
    const double third = face_area(V, F, f) / 3.0;
    for (int k = 0; k < 3; ++k) area[F(f, k)] += third;
  }
  return area.unaryExpr([](double a) { return a > 0 ? 1.0 / a : 0.0; });
}

double redistribution_rho(const Eigen::VectorXd& surface_curvature, const Vertices& V, const Faces& F) {
  return spearman_correlation(surface_curvature, vertex_density(V, F));
}

EdgeErrorStats edge_error_stats(const Vertices& V, const Topology& topology, const Curvature& surface) {
  std::vector<Eigen::Matrix3d> tensors(static_cast<std::size_t>(surface.k1.size()));
  for (Index i = 0; i < surface.k1.size(); ++i) tensors[static_cast<std::size_t>(i)] = surface.absolute_tensor(i);
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
  Eigen::VectorXd delta(ne);
  for (Index e = 0; e < ne; ++e) {
    const Index i = topology.edges(e, 0), j = topology.edges(e, 1);
    const Eigen::Vector3d d = (V.row(j) - V.row(i)).transpose();
    // Eq. 2-4 (f_em = the mean of both endpoints' quadratic forms), divided by 8 (docs/metrics.md).
    const double f_em = 0.5 * (d.dot(surface_tensors[static_cast<std::size_t>(i)] * d) +
                               d.dot(surface_tensors[static_cast<std::size_t>(j)] * d));
    delta[e] = f_em / 8.0;
  }
  stats.mean = delta.mean();
  if (stats.mean > 0) {
    stats.max_over_mean = delta.maxCoeff() / stats.mean;
    stats.coefficient_of_variation = std::sqrt((delta.array() - stats.mean).square().mean()) / stats.mean;
  }
  return stats;
}

}  // namespace vertexflow
