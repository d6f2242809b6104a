// FaceBoxTree (src/metrics/face_box_tree.h), the search behind DistanceQuery: its contract is
// that a search visits every face whose triangle lies within the bound, whatever the mesh's
// layout, including the layouts its radix splits handle apart (equal Morton codes, one face).
#include "shapes.h"
#include "test_support.h"

#include "metrics/face_box_tree.h"

#include <gtest/gtest.h>

#include <tbb/global_control.h>

#include <cmath>
#include <limits>
#include <random>
#include <set>
#include <vector>

namespace vertexflow {
namespace {

// Squared distance from q to the triangle's bounding box: a lower bound of its distance.
double squared_distance_to_face_box(const Eigen::Vector3d& q, const Vertices& V, const Faces& F, Index f) {
  Eigen::Vector3d lo = V.row(F(f, 0)).transpose(), hi = lo;
  for (int k = 1; k < 3; ++k) {
    lo = lo.cwiseMin(V.row(F(f, k)).transpose());
    hi = hi.cwiseMax(V.row(F(f, k)).transpose());
  }
  return (lo - q).cwiseMax(q - hi).cwiseMax(0.0).squaredNorm();
}

// The faces a search with a fixed bound visits, against every face whose box is within it.
void expect_visits_every_face_within(const Vertices& V, const Faces& F, int queries, double radius, unsigned seed) {
  const FaceBoxTree tree(V, F);
  const Eigen::Vector3d lo = V.colwise().minCoeff().transpose(), hi = V.colwise().maxCoeff().transpose();
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> unit(-0.1, 1.1);
  std::size_t visited_total = 0;
  for (int i = 0; i < queries; ++i) {
    Eigen::Vector3d q;
    for (int a = 0; a < 3; ++a) q[a] = lo[a] + unit(random) * (hi[a] - lo[a]);
    double bound = radius * radius;
    std::set<Index> visited;
    const double at[3] = {q.x(), q.y(), q.z()};
    tree.search(at, bound, [&](Index f) { EXPECT_TRUE(visited.insert(f).second) << "face " << f << " twice"; });
    for (Index f = 0; f < F.rows(); ++f) {
      if (squared_distance_to_face_box(q, V, F, f) <= radius * radius) {
        ASSERT_TRUE(visited.count(f)) << "query " << i << " missed face " << f;
      }
    }
    visited_total += visited.size();
  }
  // Pruning works: far fewer visits than faces times queries (would fail for a tree that
  // visited everything).
  EXPECT_LT(visited_total, static_cast<std::size_t>(queries) * static_cast<std::size_t>(F.rows()) / 4);
}

TEST(FaceBoxTree, VisitsEveryFaceWithinTheBound) {
  const Mesh torus = test::torus(1.0, 0.3, 60, 25);  // 3,000 faces
  expect_visits_every_face_within(torus.V, torus.F, 200, 0.15, 1);
  const Mesh sphere = test::icosphere(1.0, 4);
  expect_visits_every_face_within(sphere.V, sphere.F, 200, 0.1, 2);
}

// Faces whose centroids share one Morton cell (split in halves, not by bits) and a mesh of one
// face (the root a leaf) are searched alike; an empty mesh visits nothing.
TEST(FaceBoxTree, EqualCodesOneFaceAndNoFace) {
  const Mesh torus = test::torus(1.0, 0.3, 60, 25);
  Faces many(4000, 3);
  for (Index f = 0; f < many.rows(); ++f) many.row(f) = torus.F.row(f % 7);  // 7 triangles, repeated
  expect_visits_every_face_within(torus.V, many, 50, 0.3, 3);
  Faces one(1, 3);
  one << torus.F.row(0);
  const FaceBoxTree single(torus.V, one);
  const double at[3] = {10, 10, 10};
  double bound = std::numeric_limits<double>::infinity();
  int visits = 0;
  single.search(at, bound, [&](Index f) {
    EXPECT_EQ(f, 0);
    ++visits;
  });
  EXPECT_EQ(visits, 1);
  const FaceBoxTree empty(torus.V, Faces(0, 3));
  empty.search(at, bound, [&](Index) { ADD_FAILURE() << "a face of no faces"; });
}

// The tree depends on the mesh only: built on one thread or two, a search visits the same faces
// in the same order (on a mesh large enough for parallel tasks).
TEST(FaceBoxTree, SameTreeForOneAndTwoThreads) {
  const Mesh mesh = test::torus(1.0, 0.3, 500, 201);  // 201,000 faces
  const FaceBoxTree two(mesh.V, mesh.F);
  const double at[3] = {mesh.V(12345, 0), mesh.V(12345, 1), mesh.V(12345, 2)};  // on the surface
  std::vector<Index> one_order, two_order;
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
    const FaceBoxTree one(mesh.V, mesh.F);
    double bound = 0.05 * 0.05;
    one.search(at, bound, [&](Index f) { one_order.push_back(f); });
    EXPECT_EQ(one.memory_bytes(), two.memory_bytes());
  }
  double bound = 0.05 * 0.05;
  two.search(at, bound, [&](Index f) { two_order.push_back(f); });
  EXPECT_EQ(one_order, two_order);
  EXPECT_GT(one_order.size(), 10u);
}

}  // namespace
}  // namespace vertexflow
