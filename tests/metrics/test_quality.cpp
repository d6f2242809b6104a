// Triangle quality 2r/R against closed forms and an independent evaluation via r = A/s and
// R = abc/(4A).
#include "test_support.h"

#include "vertexflow/io.h"
#include "vertexflow/quality.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace vertexflow {
namespace {

Mesh one_triangle(const Eigen::RowVector3d& a, const Eigen::RowVector3d& b, const Eigen::RowVector3d& c) {
  Mesh mesh;
  mesh.V.resize(3, 3);
  mesh.V << a, b, c;
  mesh.F.resize(1, 3);
  mesh.F << 0, 1, 2;
  return mesh;
}

double radius_ratio_from_radii(const Eigen::Vector3d& p, const Eigen::Vector3d& q, const Eigen::Vector3d& r) {
  const double a = (q - r).norm(), b = (r - p).norm(), c = (p - q).norm();
  const double area = 0.5 * (q - p).cross(r - p).norm();
  const double inradius = area / (0.5 * (a + b + c));
  const double circumradius = a * b * c / (4 * area);
  return 2 * inradius / circumradius;
}

TEST(TriangleQuality, ClosedForms) {
  const Mesh equilateral = one_triangle({0, 0, 0}, {1, 0, 0}, {0.5, std::sqrt(3.0) / 2, 0});
  EXPECT_NEAR(triangle_quality(equilateral.V, equilateral.F)[0], 1.0, 1e-15);
  // Right isosceles: 2r/R = 2(sqrt 2 - 1).
  const Mesh right = one_triangle({0, 0, 0}, {1, 0, 0}, {0, 1, 0});
  EXPECT_NEAR(triangle_quality(right.V, right.F)[0], 2 * (std::sqrt(2.0) - 1), 1e-15);
  const Mesh collinear = one_triangle({0, 0, 0}, {1, 0, 0}, {3, 0, 0});
  EXPECT_EQ(triangle_quality(collinear.V, collinear.F)[0], 0.0);
  const Mesh point = one_triangle({1, 1, 1}, {1, 1, 1}, {1, 1, 1});
  EXPECT_EQ(triangle_quality(point.V, point.F)[0], 0.0);
}

TEST(TriangleQuality, AgreesWithRadiiAndIsInvariant) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  const Eigen::Matrix3d rotation = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Vector3d p(u(rng), u(rng), u(rng)), q(u(rng), u(rng), u(rng)), r(u(rng), u(rng), u(rng));
    const Mesh m = one_triangle(p.transpose(), q.transpose(), r.transpose());
    const double value = triangle_quality(m.V, m.F)[0];
    EXPECT_NEAR(value, radius_ratio_from_radii(p, q, r), 1e-9);
    // Rotation, translation, scale.
    const Eigen::Vector3d t(3, -2, 5);
    const Mesh moved = one_triangle((37.5 * rotation * p + t).transpose(), (37.5 * rotation * q + t).transpose(),
                                    (37.5 * rotation * r + t).transpose());
    EXPECT_NEAR(triangle_quality(moved.V, moved.F)[0], value, 1e-9);
  }
}

TEST(QualityStats, SummaryOfKnownValues) {
  Eigen::VectorXd q(20);
  for (int i = 0; i < 20; ++i) q[i] = i / 20.0;  // 0, 0.05, ..., 0.95
  const QualityStats s = summarize_quality(q);
  EXPECT_EQ(s.min, 0.0);
  EXPECT_NEAR(s.mean, 0.475, 1e-15);
  EXPECT_NEAR(s.fraction_below_0_3, 6 / 20.0, 1e-15);  // 0 .. 0.25
  EXPECT_EQ(s.p5, 0.0);                                // nearest rank: ceil(0.05 * 20) = 1st value
  for (int b = 0; b < 10; ++b) EXPECT_EQ(s.histogram[static_cast<std::size_t>(b)], 2) << b;
  EXPECT_EQ(summarize_quality(Eigen::VectorXd()).mean, 0.0);
}

TEST(QualityStats, IcosahedronIsPerfect) {
  const Mesh mesh = read_mesh(test::data_path("icosahedron_binary.stl"));
  const QualityStats s = summarize_quality(triangle_quality(mesh.V, mesh.F));
  EXPECT_NEAR(s.min, 1.0, 1e-6);
  EXPECT_EQ(s.histogram[9], 20);
}

}  // namespace
}  // namespace vertexflow
