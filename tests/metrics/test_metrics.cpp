// Redistribution and edge-error metrics against hand-computed values.
#include "shapes.h"
#include "test_support.h"

#include "vertexflow/metrics.h"
#include "vertexflow/statistics.h"

#include <gtest/gtest.h>

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

}  // namespace
}  // namespace vertexflow
