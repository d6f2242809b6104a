// Occluding contours (lines.h) on a sphere, whose contour is known exactly: orthographic, the
// great circle across the view; in perspective, the circle where the tangent cone from the eye
// touches; on a hemisphere seen from the side, an open arc ending at its boundary.
#include "shapes.h"
#include "test_support.h"

#include "vertexflow/curvature.h"
#include "vertexflow/io.h"
#include "vertexflow/lines.h"

#include <gtest/gtest.h>

#include <iostream>

namespace vertexflow {
namespace {

Index total_points(const std::vector<Polyline>& lines) {
  Index sum = 0;
  for (const Polyline& l : lines) sum += l.points.rows();
  return sum;
}

// On an icosphere the vertex normals are the positions (Max 1999 weights are exact there), so g
// is linear in the position along an edge and the crossings lie exactly on the analytic contour.
TEST(OccludingContours, SphereOrthographicIsTheGreatCircleAcrossTheView) {
  const Mesh sphere = test::icosphere(1.0, 4);
  const Vertices normals = vertex_normals(sphere.V, sphere.F);
  for (const Eigen::Vector3d& d :
       {Eigen::Vector3d(0, 0, -1), Eigen::Vector3d(1, 2, 3).normalized(), Eigen::Vector3d(-0.3, 1, 0.1).normalized()}) {
    View view;
    view.orthographic = true;
    view.direction = d;
    const std::vector<Polyline> lines = occluding_contours(sphere.V, sphere.F, normals, view);
    ASSERT_EQ(lines.size(), 1u);
    EXPECT_TRUE(lines[0].closed);
    const Eigen::VectorXd across = (lines[0].points * d).cwiseAbs();
    const Eigen::VectorXd radius = lines[0].points.rowwise().norm();
    std::cout << "[measured] sphere, view " << d.transpose() << ": " << lines[0].points.rows()
              << " points, largest |p . d| " << across.maxCoeff() << ", radius " << radius.minCoeff() << " .. "
              << radius.maxCoeff() << "\n";
    EXPECT_GT(lines[0].points.rows(), 100);  // measured 178-206 (a 2562-vertex icosphere)
    EXPECT_LT(across.maxCoeff(), 1e-12);
    EXPECT_GT(radius.minCoeff(), 0.995);  // chords of edges about 0.06 long
    EXPECT_LE(radius.maxCoeff(), 1.0 + 1e-12);
  }
}

TEST(OccludingContours, SpherePerspectiveIsTheCircleOfTangency) {
  const Mesh sphere = test::icosphere(1.0, 4);
  View view;
  view.eye = Eigen::Vector3d(0, 0, 5);
  const std::vector<Polyline> lines = occluding_contours(sphere.V, sphere.F, vertex_normals(sphere.V, sphere.F), view);
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_TRUE(lines[0].closed);
  // p . eye = |p|^2 = 1 on the circle of tangency: z = 1/5.
  const Eigen::VectorXd z = lines[0].points.col(2);
  EXPECT_LT((z.array() - 0.2).abs().maxCoeff(), 1e-12);
}

TEST(OccludingContours, HemisphereFromTheSideIsAnOpenArc) {
  const Mesh hemisphere = read_mesh(test::data_path("hemisphere.off"));
  const Vertices normals = vertex_normals(hemisphere.V, hemisphere.F);
  // Its boundary circle lies in a coordinate plane; look along an axis in that plane.
  const Eigen::Vector3d extent = hemisphere.V.colwise().maxCoeff() - hemisphere.V.colwise().minCoeff();
  Index flat = 0;
  extent.minCoeff(&flat);  // the axis of the dome
  View view;
  view.orthographic = true;
  view.direction = Eigen::Vector3d::Unit((flat + 1) % 3);
  const std::vector<Polyline> lines = occluding_contours(hemisphere.V, hemisphere.F, normals, view);
  std::cout << "[measured] hemisphere from the side: " << lines.size() << " polylines, " << total_points(lines)
            << " points\n";
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_FALSE(lines[0].closed);
  EXPECT_GT(lines[0].points.rows(), 10);
}

TEST(OccludingContours, DeterministicAndRefusesBadNormals) {
  const Mesh torus = test::torus(1.0, 0.4, 48, 24);
  const Vertices normals = vertex_normals(torus.V, torus.F);
  View view;
  view.eye = Eigen::Vector3d(0.3, -4, 2);
  const auto one = test::with_threads(1, [&] { return occluding_contours(torus.V, torus.F, normals, view); });
  const auto two = test::with_threads(2, [&] { return occluding_contours(torus.V, torus.F, normals, view); });
  ASSERT_EQ(one.size(), two.size());
  ASSERT_GE(one.size(), 2u);  // the outer silhouette and the inner hole's
  for (std::size_t i = 0; i < one.size(); ++i) EXPECT_EQ(one[i].points, two[i].points);
  EXPECT_THROW(occluding_contours(torus.V, torus.F, normals.topRows(3), view), std::invalid_argument);
}

}  // namespace
}  // namespace vertexflow
