// Redistribution and edge-error metrics against hand-computed values.
#include "shapes.h"
#include "test_support.h"

#include "vertexflow/metrics.h"
#include "vertexflow/statistics.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace vertexflow {
namespace {

TEST(Spearman, KnownValues) {
  Eigen::VectorXd a(5), b(5), c(5);
  a << 1, 2, 3, 4, 5;
  b << 10, 20, 25, 100, 1000;  // monotone, not linear
  c << 5, 4, 3, 2, 1;
  EXPECT_NEAR(spearman_correlation(a, b), 1.0, 1e-15);
  EXPECT_NEAR(spearman_correlation(a, c), -1.0, 1e-15);
  // With ties: x = (1, 2, 2, 3), y = (1, 3, 2, 4): ranks x = (1, 2.5, 2.5, 4), y = (1, 3, 2, 4).
  Eigen::VectorXd x(4), y(4);
  x << 1, 2, 2, 3;
  y << 1, 3, 2, 4;
  // Pearson of the ranks, centred at 2.5: x' = (-1.5, 0, 0, 1.5), y' = (-1.5, 0.5, -0.5, 1.5).
  EXPECT_NEAR(spearman_correlation(x, y), 4.5 / std::sqrt(4.5 * 5.0), 1e-15);
  EXPECT_EQ(spearman_correlation(Eigen::VectorXd::Ones(4), y), 0.0);
}

TEST(VertexDensity, InverseOfOneThirdOfTheIncidentArea) {
  Mesh mesh;
  mesh.V.resize(4, 3);
  mesh.V << 0, 0, 0, 2, 0, 0, 0, 2, 0, 2, 2, 0;
  mesh.F.resize(2, 3);
  mesh.F << 0, 1, 2, 1, 3, 2;  // two triangles of area 2
  const Eigen::VectorXd density = vertex_density(mesh.V, mesh.F);
  EXPECT_NEAR(density[0], 1.0 / (2.0 / 3.0), 1e-15);
  EXPECT_NEAR(density[1], 1.0 / (4.0 / 3.0), 1e-15);
}

TEST(EdgeError, UniformOnASphere) {
  // On a sphere of radius R every direction has k = 1/R, so delta_e = |e|^2 / (8 R): its CV is
  // the CV of the squared edge lengths.
  const Mesh mesh = test::icosphere(2.0, 3);
  const Topology topology = build_topology(mesh.F, mesh.num_vertices());
  const Curvature c = principal_curvatures(mesh.V, mesh.F, topology);
  const EdgeErrorStats stats = edge_error_stats(mesh.V, topology, c);
  Eigen::VectorXd expected(topology.num_edges());
  for (Index e = 0; e < topology.num_edges(); ++e)
    expected[e] = (mesh.V.row(topology.edges(e, 0)) - mesh.V.row(topology.edges(e, 1))).squaredNorm() / (8 * 2.0);
  EXPECT_NEAR(stats.mean, expected.mean(), 0.01 * expected.mean());
  const double cv = std::sqrt((expected.array() - expected.mean()).square().mean()) / expected.mean();
  EXPECT_NEAR(stats.coefficient_of_variation, cv, 0.02);
  EXPECT_NEAR(stats.max_over_mean, expected.maxCoeff() / expected.mean(), 0.05);
}

TEST(Percentile, NearestRank) {
  const std::vector<double> values = {5, 1, 4, 2, 3};
  EXPECT_EQ(percentile(values, 0), 1.0);
  EXPECT_EQ(percentile(values, 20), 1.0);  // rank ceil(0.2 * 5) = 1
  EXPECT_EQ(percentile(values, 21), 2.0);
  EXPECT_EQ(percentile(values, 50), 3.0);
  EXPECT_EQ(percentile(values, 100), 5.0);
  EXPECT_EQ(percentile({}, 50), 0.0);
  EXPECT_THROW(percentile(values, -0.5), std::invalid_argument);
  EXPECT_THROW(percentile(values, 100.5), std::invalid_argument);
  EXPECT_THROW(percentile(values, std::nan("")), std::invalid_argument);
}

// Ranks by a radix sort of the values' bits: on many ties (signed zeros among them), the
// coefficient a plain average-rank computation gives, bit for bit.
TEST(Spearman, ManyTiesMatchAPlainComputation) {
  const Eigen::Index n = 20000;
  Eigen::VectorXd a(n), b(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    a[i] = static_cast<double>((i * 7919) % 37);  // 37 values, about 540 ties each
    b[i] = static_cast<double>((i * 104729) % 1009) - 0.5 * static_cast<double>(i % 3);
  }
  // Signed zeros are equal values: one tie, whatever their bits.
  for (Eigen::Index i = 0; i < n; i += 5) a[i] = i % 2 ? -0.0 : 0.0;
  const auto plain_ranks = [](const Eigen::VectorXd& x) {
    std::vector<Eigen::Index> order(static_cast<std::size_t>(x.size()));
    for (Eigen::Index i = 0; i < x.size(); ++i) order[static_cast<std::size_t>(i)] = i;
    std::stable_sort(order.begin(), order.end(), [&](Eigen::Index p, Eigen::Index q) { return x[p] < x[q]; });
    Eigen::VectorXd r(x.size());
    for (Eigen::Index i = 0; i < x.size();) {
      Eigen::Index j = i;
      while (j + 1 < x.size() && x[order[static_cast<std::size_t>(j + 1)]] == x[order[static_cast<std::size_t>(i)]])
        ++j;
      for (Eigen::Index k = i; k <= j; ++k)
        r[order[static_cast<std::size_t>(k)]] = 0.5 * static_cast<double>(i + j) + 1.0;
      i = j + 1;
    }
    return r;
  };
  const Eigen::VectorXd ra = plain_ranks(a).array() - (static_cast<double>(n) + 1) / 2;
  const Eigen::VectorXd rb = plain_ranks(b).array() - (static_cast<double>(n) + 1) / 2;
  const double expected = ra.dot(rb) / std::sqrt(ra.squaredNorm() * rb.squaredNorm());
  EXPECT_EQ(spearman_correlation(a, b), expected);
  EXPECT_NE(expected, 0.0);
}

// Several percentiles from one copy: each is percentile()'s, in any order of the requests.
TEST(Percentile, SeveralAtOnceAreEachPercentile) {
  std::vector<double> values;
  for (int i = 0; i < 1001; ++i) values.push_back(static_cast<double>((i * 613) % 101));  // with ties
  const std::vector<double> ps = {95, 5, 50, 99, 50, 0, 100, 21.5};
  const std::vector<double> got = percentiles(values, ps);
  ASSERT_EQ(got.size(), ps.size());
  for (std::size_t k = 0; k < ps.size(); ++k) EXPECT_EQ(got[k], percentile(values, ps[k])) << "p = " << ps[k];
  EXPECT_EQ(percentiles({}, {5, 95}), (std::vector<double>{0.0, 0.0}));
  EXPECT_THROW(percentiles(values, {5, 100.5}), std::invalid_argument);
  EXPECT_THROW(percentiles({}, {-1}), std::invalid_argument);
}

}  // namespace
}  // namespace vertexflow
