#include "vertexflow/metrics.h"

#include "numerics/parallel.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace vertexflow {
namespace {

// The values in increasing order, ties (equal bits) in index order: an LSD radix sort of the
// doubles' bits mapped to unsigned integers of the same order (negatives' bits inverted, the
// sign bit set on the others), 11 bits a pass, passes on which every key has the same digit
// skipped. Written here because neither TBB nor the standard library has a radix sort: with the
// CLI's allocator (jemalloc, huge pages) spearman_correlation of two 10M-value vectors took
// 1.5 s with a parallel comparison sort of (value, index) pairs, 0.8 s with this one on one
// thread. Returns the indices in that order (x.size() of them).
std::unique_ptr<std::uint32_t[]> order_by_value(const Eigen::VectorXd& x) {
  const std::size_t n = static_cast<std::size_t>(x.size());
  constexpr int kBits = 11, kPasses = (64 + kBits - 1) / kBits;
  constexpr std::size_t kBuckets = std::size_t{1} << kBits;
  // Not zero-filled: every slot is written before it is read.
  auto key = std::make_unique_for_overwrite<std::uint64_t[]>(n);
  auto key_out = std::make_unique_for_overwrite<std::uint64_t[]>(n);
  auto index = std::make_unique_for_overwrite<std::uint32_t[]>(n);
  auto index_out = std::make_unique_for_overwrite<std::uint32_t[]>(n);
  std::vector<std::array<std::size_t, kBuckets>> count(kPasses);
  for (auto& c : count) c.fill(0);
  for (std::size_t i = 0; i < n; ++i) {
    const auto bits = std::bit_cast<std::uint64_t>(x[static_cast<Eigen::Index>(i)]);
    key[i] = bits >> 63 ? ~bits : bits | std::uint64_t{1} << 63;
    index[i] = static_cast<std::uint32_t>(i);
    for (int pass = 0; pass < kPasses; ++pass)
      ++count[static_cast<std::size_t>(pass)][key[i] >> (pass * kBits) & (kBuckets - 1)];
  }
  for (int pass = 0; pass < kPasses; ++pass) {
    auto& c = count[static_cast<std::size_t>(pass)];
    if (std::find(c.begin(), c.end(), n) != c.end()) continue;  // one digit for all: nothing moves
    std::size_t start = 0;
    for (std::size_t& bucket : c) start += std::exchange(bucket, start);
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t to = c[key[i] >> (pass * kBits) & (kBuckets - 1)]++;
      key_out[to] = key[i];
      index_out[to] = index[i];
    }
    key.swap(key_out);
    index.swap(index_out);
  }
  return index;
}

// Ranks 1..n, ties sharing their average rank.
Eigen::VectorXd ranks(const Eigen::VectorXd& x) {
  const Eigen::Index n = x.size();
  const std::unique_ptr<std::uint32_t[]> order = order_by_value(x);
  const auto value = [&](Eigen::Index k) { return x[order[static_cast<std::size_t>(k)]]; };
  Eigen::VectorXd r(n);
  for (Eigen::Index i = 0; i < n;) {
    Eigen::Index j = i;
    while (j + 1 < n && value(j + 1) == value(i)) ++j;
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

namespace {

// edge_error_stats with vertex i's tensor K_i = tensor(i).
template <class TensorOf>
EdgeErrorStats edge_error_stats_of(const Vertices& V, const Topology& topology, TensorOf&& tensor) {
  EdgeErrorStats stats;
  const Index ne = topology.num_edges();
  if (ne == 0) return stats;
  // The edges' errors in parallel; the sums below are Eigen's, over the whole vector.
  Eigen::VectorXd delta(ne);
  parallel_for_index(ne, [&](Index e) {
    const Index i = topology.edges(e, 0), j = topology.edges(e, 1);
    const Eigen::Vector3d d = (V.row(j) - V.row(i)).transpose();
    // Eq. 2-4 (f_em = the mean of both endpoints' quadratic forms), divided by 8 (docs/metrics.md).
    const double f_em = 0.5 * (d.dot(tensor(i) * d) + d.dot(tensor(j) * d));
    delta[e] = f_em / 8.0;
  });
  stats.mean = delta.mean();
  if (stats.mean > 0) {
    stats.max_over_mean = delta.maxCoeff() / stats.mean;
    stats.coefficient_of_variation = std::sqrt((delta.array() - stats.mean).square().mean()) / stats.mean;
  }
  return stats;
}

void check_count(std::size_t tensors, const Vertices& V) {
  if (tensors != static_cast<std::size_t>(V.rows()))
    throw std::invalid_argument("edge_error_stats: " + std::to_string(tensors) + " tensors for " +
                                std::to_string(V.rows()) + " vertices");
}

}  // namespace

EdgeErrorStats edge_error_stats(const Vertices& V, const Topology& topology, const Curvature& surface) {
  check_count(static_cast<std::size_t>(surface.k1.size()), V);
  // Each K_i computed where an edge needs it rather than stored: the same values, without 72
  // bytes per vertex (700 MB at 10M vertices, each page a fault on a VM, docs/benchmarks.md).
  return edge_error_stats_of(V, topology, [&](Index i) { return surface.absolute_tensor(i); });
}

EdgeErrorStats edge_error_stats(const Vertices& V, const Topology& topology,
                                const std::vector<Eigen::Matrix3d>& surface_tensors) {
  check_count(surface_tensors.size(), V);
  return edge_error_stats_of(
      V, topology, [&](Index i) -> const Eigen::Matrix3d& { return surface_tensors[static_cast<std::size_t>(i)]; });
}

}  // namespace vertexflow
