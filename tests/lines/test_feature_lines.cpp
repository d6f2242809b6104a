// Suggestive contours, ridges and valleys (lines.h) on surfaces whose lines are known: the
// inflection circle of a bump seen from above, a cylinder seen side-on (none), the equators of
// an elliptic torus, the rounded edges of a cube; and their invariances.
#include "shapes.h"
#include "test_support.h"

#include "vertexflow/curvature.h"
#include "vertexflow/lines.h"
#include "vertexflow/topology.h"

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <numbers>

namespace vertexflow {
namespace {

double total_length(const std::vector<Polyline>& lines, LineType type) {
  double sum = 0;
  for (const Polyline& l : lines) {
    if (l.type != type) continue;
    for (Index i = 1; i < l.points.rows(); ++i) sum += (l.points.row(i) - l.points.row(i - 1)).norm();
    if (l.closed && l.points.rows() > 1) sum += (l.points.row(0) - l.points.row(l.points.rows() - 1)).norm();
  }
  return sum;
}

// Every point of every line of `type`, as rows.
std::vector<Eigen::Vector3d> points_of(const std::vector<Polyline>& lines, LineType type) {
  std::vector<Eigen::Vector3d> out;
  for (const Polyline& l : lines)
    if (l.type == type)
      for (Index i = 0; i < l.points.rows(); ++i) out.push_back(l.points.row(i).transpose());
  return out;
}

LineOptions only(LineType type) {
  LineOptions o;
  o.contours = type == LineType::Contour;
  o.suggestive_contours = type == LineType::SuggestiveContour;
  o.ridges = type == LineType::Ridge;
  o.valleys = type == LineType::Valley;
  return o;
}

View orthographic(const Eigen::Vector3d& direction) {
  View view;
  view.orthographic = true;
  view.direction = direction;
  return view;
}

// z = h exp(-r^2 / 2 s^2) seen from straight above: w points uphill (towards the centre), the
// radial curvature is the profile's, zero at the inflection r = s, and it increases towards the
// centre there. So the suggestive contour is the circle r = s.
TEST(SuggestiveContours, BumpFromAboveIsItsInflectionCircle) {
  const double s = 0.35, h = 0.3, half = 1.0;
  const int n = 80;
  const Mesh bump =
      test::height_field(half, n, [&](double x, double y) { return h * std::exp(-(x * x + y * y) / (2 * s * s)); });
  LineOptions options = only(LineType::SuggestiveContour);
  options.suggestive_threshold = 0;  // the plain definition: k_r = 0, D_w k_r > 0
  const std::vector<Polyline> lines = feature_lines(bump.V, bump.F, orthographic({0, 0, -1}), options);
  const std::vector<Eigen::Vector3d> points = points_of(lines, LineType::SuggestiveContour);
  const double edge = 2 * half / n;
  double worst = 0;
  for (const Eigen::Vector3d& p : points) worst = std::max(worst, std::abs(p.head<2>().norm() - s));
  const double length = total_length(lines, LineType::SuggestiveContour);
  std::cout << "[measured] bump: " << lines.size() << " suggestive contours, " << points.size()
            << " points, largest |r - s| " << worst << " (edge " << edge << "), length " << length << " of "
            << 2 * std::numbers::pi * s << "\n";
  ASSERT_GT(points.size(), 50u);
  EXPECT_LT(worst, edge);                                     // measured 0.0046, edge 0.025
  EXPECT_NEAR(length, 2 * std::numbers::pi * s, 0.05 * 2.2);  // measured within 0.3%
  // Seen from below, the surface faces away: no suggestive contour.
  EXPECT_TRUE(feature_lines(bump.V, bump.F, orthographic({0, 0, 1}), options).empty());
  // The threshold culls it: tan(theta) D_w k_r at r = s is about 2.7 here (lines.h; L = 2.9).
  options.suggestive_threshold = 100 * 8.4;  // 100 / L^2 in 1 / length^2
  EXPECT_TRUE(feature_lines(bump.V, bump.F, orthographic({0, 0, -1}), options).empty());
}

// A cylinder seen side-on: k_r = k1 sin^2(theta) > 0 everywhere but on the line facing the
// viewer, where it touches 0 without crossing and tan(theta) = 0 fails the threshold.
TEST(SuggestiveContours, CylinderSideOnHasNoneInsideItsOutline) {
  const Mesh cylinder = test::cylinder(0.5, 2.0, 64, 32);
  const LineOptions options = only(LineType::SuggestiveContour);
  for (const Eigen::Vector3d& d :
       {Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0.6, 0.8, 0), Eigen::Vector3d(1, 1, 0.2)}) {
    const std::vector<Polyline> lines = feature_lines(cylinder.V, cylinder.F, orthographic(d), options);
    EXPECT_EQ(total_length(lines, LineType::SuggestiveContour), 0.0) << d.transpose();
  }
  View perspective;
  perspective.eye = Eigen::Vector3d(3, 0.5, 1);
  EXPECT_EQ(total_length(feature_lines(cylinder.V, cylinder.F, perspective, options), LineType::SuggestiveContour),
            0.0);
}

// The elliptic torus (a > b): the meridian curvature a / b^2 = 10 is k1 and is largest on both
// equators, where the parallel curvature is 1 / 1.4 and -1 / 0.6: ridges on the outer and the
// inner equator, no valley. Reversing the orientation makes them valleys.
TEST(RidgesAndValleys, EllipticTorusRidgesLieOnItsEquators) {
  const double R = 1.0, a = 0.4, b = 0.2;
  Mesh torus = test::elliptic_torus(R, a, b, 160, 64);
  LineOptions options = only(LineType::Ridge);
  options.valleys = true;
  options.ridge_threshold = 10;  // k >= 10 / L = 2.4: the meridian curvature is 1.25 .. 10
  const View view = orthographic({0, 0, -1});
  const auto check = [&](const std::vector<Polyline>& lines, LineType expected, LineType absent) {
    const double edge = 2 * std::numbers::pi * (R - a) / 160;  // the shortest edge along a parallel
    double worst = 0;
    for (const Eigen::Vector3d& p : points_of(lines, expected)) {
      const double rho = p.head<2>().norm();
      worst = std::max({worst, std::abs(p.z()), std::min(std::abs(rho - (R + a)), std::abs(rho - (R - a)))});
    }
    const double equators = 2 * std::numbers::pi * ((R + a) + (R - a));
    const double length = total_length(lines, expected);
    std::cout << "[measured] elliptic torus: " << line_type_name(expected) << " length " << length << " of " << equators
              << ", largest distance from an equator " << worst << " (edge " << edge << ")\n";
    EXPECT_LT(worst, edge);             // measured 1.6e-3, edge 0.024
    EXPECT_GT(length, 0.9 * equators);  // measured 1.00
    EXPECT_LT(length, 1.1 * equators);
    EXPECT_EQ(total_length(lines, absent), 0.0);
  };
  check(feature_lines(torus.V, torus.F, view, options), LineType::Ridge, LineType::Valley);
  torus.F.col(1).swap(torus.F.col(2));
  check(feature_lines(torus.V, torus.F, view, options), LineType::Valley, LineType::Ridge);
}

// A rounded cube: the quarter-cylinders along its edges carry its only curvature (k1 = 1 / r,
// corners umbilic), so its ridges run along them and nowhere on the flat faces; no valleys.
TEST(RidgesAndValleys, RoundedCubeHasRidgesAlongItsRoundedEdgesOnly) {
  const double core = 0.6, radius = 0.25;
  const int n = 48;
  const Mesh cube = test::rounded_cube(core, radius, n);
  LineOptions options = only(LineType::Ridge);
  options.valleys = true;
  options.ridge_threshold = 5;  // k >= 5 / L = 1.7, L = 2.94; the edges have 4
  const std::vector<Polyline> lines = feature_lines(cube.V, cube.F, orthographic({0, 0, -1}), options);
  const double cell = 2 * (core + radius) / n;
  int outside = 0;
  std::array<double, 12> along{};  // ridge points near each of the 12 edges, by (axis, signs)
  for (const Eigen::Vector3d& p : points_of(lines, LineType::Ridge)) {
    // On a rounded edge at least two coordinates are beyond the core.
    int beyond = 0, axis = -1;
    for (int d = 0; d < 3; ++d) {
      if (std::abs(p[d]) > core - cell)
        ++beyond;
      else
        axis = d;
    }
    if (beyond < 2) {
      ++outside;
      continue;
    }
    if (axis >= 0) {
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      along[static_cast<std::size_t>(4 * axis + 2 * (p[u] > 0) + (p[v] > 0))] += 1;
    }
  }
  const double length = total_length(lines, LineType::Ridge);
  std::cout << "[measured] rounded cube: ridge length " << length << " (12 edges of " << 2 * core << "), " << outside
            << " points on flat faces, fewest points along one edge " << *std::min_element(along.begin(), along.end())
            << "\n";
  EXPECT_EQ(outside, 0);
  EXPECT_GT(*std::min_element(along.begin(), along.end()), 10);  // measured 140
  EXPECT_GT(length, 0.5 * 12 * 2 * core);  // measured 39.6: parallel lines on the plateau of 1 / r
  EXPECT_EQ(total_length(lines, LineType::Valley), 0.0);
}

// smoothing_scale smooths the curvature over a distance: on a noisy sphere (no true ridge or
// valley) it removes most of the noise's lines, which one ring of smoothing leaves.
TEST(FeatureLines, SmoothingScaleRemovesNoiseLines) {
  const Mesh noisy = test::noisy_scan(test::icosphere(1.0, 5), 0.1, 0.0, 7);
  LineOptions options = only(LineType::Ridge);
  options.valleys = true;
  options.ridge_threshold = 5;  // k >= 5 / L = 1.44; the sphere's own k is 1, noise adds more
  const auto noise = [&](double scale) {
    options.smoothing_scale = scale;
    const std::vector<Polyline> lines = feature_lines(noisy.V, noisy.F, orthographic({0, 0, -1}), options);
    return total_length(lines, LineType::Ridge) + total_length(lines, LineType::Valley);
  };
  const double one_ring = noise(0), smoothed = noise(0.02);
  std::cout << "[measured] noisy sphere: ridge and valley length " << one_ring << " with one ring, " << smoothed
            << " smoothed over 2% of L\n";
  EXPECT_GT(one_ring, 30.0);            // measured 98
  EXPECT_LT(smoothed, 0.1 * one_ring);  // measured 0
  options.smoothing_scale = -1;
  EXPECT_THROW(feature_lines(noisy.V, noisy.F, orthographic({0, 0, -1}), options), std::invalid_argument);
}

// Rigid motion, uniform scale (the thresholds scale with L) and the thread count.
TEST(FeatureLines, InvariantUnderRigidMotionScaleAndThreads) {
  const Mesh torus = test::elliptic_torus(1.0, 0.4, 0.2, 96, 48);
  LineOptions options;
  options.ridge_threshold = 10;
  options.suggestive_threshold = 1;  // the default 20 leaves none on this smooth torus
  const View view = orthographic(Eigen::Vector3d(0.3, 1, -0.6).normalized());
  const std::vector<Polyline> base = feature_lines(torus.V, torus.F, view, options);
  const auto lengths = [](const std::vector<Polyline>& lines) {
    return std::array<double, 4>{total_length(lines, LineType::Contour),
                                 total_length(lines, LineType::SuggestiveContour), total_length(lines, LineType::Ridge),
                                 total_length(lines, LineType::Valley)};
  };
  const std::array<double, 4> expected = lengths(base);
  std::cout << "[measured] torus lengths: contours " << expected[0] << ", suggestive " << expected[1] << ", ridges "
            << expected[2] << ", valleys " << expected[3] << "\n";
  EXPECT_GT(expected[0], 0);
  EXPECT_GT(expected[1], 0);  // the inner part of a torus seen obliquely has suggestive contours
  EXPECT_GT(expected[2], 0);

  const Eigen::Matrix3d rotation = (Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized())).toRotationMatrix();
  const double scale = 3.5;
  Mesh moved = torus;
  moved.V = ((scale * torus.V * rotation.transpose()).rowwise() + Eigen::RowVector3d(1, -2, 5)).eval();
  const View moved_view = orthographic(rotation * view.direction);
  const std::array<double, 4> after = lengths(feature_lines(moved.V, moved.F, moved_view, options));
  // Contours, ridges, valleys: equal to rounding. Suggestive contours: a clip at the threshold
  // moves with the curvature's rounding (1e-9 relative); measured 3.3e-4 of their length.
  const std::array<double, 4> tolerance{1e-6, 1e-3, 1e-6, 1e-6};
  for (int t = 0; t < 4; ++t)
    EXPECT_NEAR(after[t], scale * expected[t], tolerance[static_cast<std::size_t>(t)] * scale * (expected[t] + 1))
        << line_type_name(static_cast<LineType>(t));

  const auto two = test::with_threads(2, [&] { return feature_lines(torus.V, torus.F, view, options); });
  const auto one = test::with_threads(1, [&] { return feature_lines(torus.V, torus.F, view, options); });
  ASSERT_EQ(one.size(), two.size());
  for (std::size_t i = 0; i < one.size(); ++i) EXPECT_EQ(one[i].points, two[i].points);
  options.ridge_threshold = -1;
  EXPECT_THROW(feature_lines(torus.V, torus.F, view, options), std::invalid_argument);
}

}  // namespace
}  // namespace vertexflow
