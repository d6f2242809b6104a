// Geometric unsharp mask: closed-form answers on the icosahedron, spheres and planes; fixed
// vertices; linearity in w; invariance under rigid motion and uniform scale.
#include "shapes.h"
#include "test_support.h"

#include "vertexflow/io.h"
#include "vertexflow/topology.h"
#include "vertexflow/unsharp.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace vertexflow {
namespace {

// The icosahedron is vertex-transitive: the five neighbours of v average to v / sqrt(5), so
// every smoothing round scales the whole shape by 1 / sqrt(5) and after k rounds
// v' = v (1 + w (1 - 5^(-k/2))).
TEST(Unsharp, IcosahedronScalesByTheClosedForm) {
  const Mesh ico = test::icosphere(2.0, 0);
  for (const int k : {1, 2, 5}) {
    for (const double w : {0.3, 1.0, -0.5}) {
      UnsharpOptions options;
      options.weight = w;
      options.smoothing_iterations = k;
      const Vertices result = unsharp_mask(ico.V, ico.F, options).V;
      const double factor = 1.0 + w * (1.0 - std::pow(5.0, -0.5 * k));
      EXPECT_LT((result - factor * ico.V).cwiseAbs().maxCoeff(), 1e-14) << "k " << k << " w " << w;
    }
  }
}

// One round on any mesh inscribed in a sphere of radius R: the radial part of v - mean(n_i) is
// R - mean(R cos theta_i) = mean(l_i^2) / (2 R) for chords l_i, so each vertex moves outwards by
// exactly w mean(l_i^2) / (2 R) along its radius. The tangential part comes from irregular
// spacing (first order in the edge length, where the radial part is second order), so only the
// icosahedron above moves purely radially.
void expect_radial_closed_form(const Mesh& sphere, double R, double position_error) {
  const Topology topology = build_topology(sphere.F, sphere.num_vertices());
  UnsharpOptions options;
  options.smoothing_iterations = 1;
  options.weight = 0.7;
  const Vertices result = unsharp_mask(sphere.V, sphere.F, options).V;
  for (Index v = 0; v < sphere.num_vertices(); ++v) {
    const Eigen::RowVector3d p = sphere.V.row(v);
    const Eigen::RowVector3d radial = p.normalized();
    double mean_sq = 0;
    const auto [begin, end] = topology.ring(v);
    for (const Index* j = begin; j != end; ++j) mean_sq += (sphere.V.row(*j) - p).squaredNorm();
    mean_sq /= static_cast<double>(end - begin);
    const Eigen::RowVector3d moved = result.row(v) - p;
    const double expected = options.weight * mean_sq / (2 * R);
    ASSERT_NEAR(moved.dot(radial), expected, 1e-9 * expected + position_error) << "vertex " << v;
    ASSERT_GT(moved.dot(radial), 0) << "vertex " << v;
  }
}

TEST(Unsharp, SphereVerticesMoveRadiallyOutwardByTheExpectedAmount) {
  expect_radial_closed_form(test::icosphere(3.0, 3), 3.0, 1e-15);
  // sphere.off: the unit sphere with coordinates printed to about 6 digits.
  expect_radial_closed_form(read_mesh(test::data_path("sphere.off")), 1.0, 1e-6);
}

TEST(Unsharp, DefaultOptionsPushEverySphereVertexOutwards) {
  const Mesh sphere = test::icosphere(1.0, 3);
  const Vertices result = unsharp_mask(sphere.V, sphere.F).V;
  const Eigen::VectorXd radius = result.rowwise().norm();
  EXPECT_GT(radius.minCoeff(), 1.0);
  // Five rounds smooth the sphere inwards by at most ~5 rounds of l^2 / (2R) (l <= 0.35 here).
  EXPECT_LT(radius.maxCoeff(), 1.0 + 0.3 * 5 * 0.35 * 0.35 / 2);
}

// A flat grid whose interior one-rings are centrally symmetric (the alternating-diagonal grid:
// valence 4 and 8): every neighbour mean is the vertex itself, so nothing moves.
Mesh flat_grid(int n) {
  Mesh grid = test::saddle(1.0, n);
  grid.V.col(2).setZero();
  return grid;
}

TEST(Unsharp, RegularPlanarGridDoesNotMove) {
  const Mesh grid = flat_grid(12);
  UnsharpOptions options;
  options.weight = 2.0;
  options.smoothing_iterations = 7;
  const Vertices result = unsharp_mask(grid.V, grid.F, options).V;
  EXPECT_LT((result - grid.V).cwiseAbs().maxCoeff(), 1e-15);
}

TEST(Unsharp, IrregularPlanarMeshStaysInItsPlane) {
  Mesh grid = flat_grid(12);
  const Topology topology = build_topology(grid.F, grid.num_vertices());
  std::mt19937 random(7);
  std::uniform_real_distribution<double> jitter(-0.03, 0.03);
  for (Index v = 0; v < grid.num_vertices(); ++v)
    if (!topology.is_boundary_vertex[static_cast<std::size_t>(v)])
      grid.V.row(v) += Eigen::RowVector3d(jitter(random), jitter(random), 0);
  const Vertices result = unsharp_mask(grid.V, grid.F).V;
  EXPECT_GT((result - grid.V).cwiseAbs().maxCoeff(), 1e-3);  // it does move, within the plane
  EXPECT_EQ(result.col(2).cwiseAbs().maxCoeff(), 0.0);
}

TEST(Unsharp, ZeroWeightIsTheIdentityAndDisplacementIsLinearInTheWeight) {
  const Mesh bunny = read_mesh(test::data_path("bunny_uniform.off"));
  UnsharpOptions options;
  options.weight = 0;
  EXPECT_EQ(unsharp_mask(bunny.V, bunny.F, options).V, bunny.V);
  options.weight = 0.3;
  const Vertices d1 = unsharp_mask(bunny.V, bunny.F, options).V - bunny.V;
  options.weight = 0.6;
  const Vertices d2 = unsharp_mask(bunny.V, bunny.F, options).V - bunny.V;
  EXPECT_GT(d1.cwiseAbs().maxCoeff(), 0.0);
  EXPECT_LT((d2 - 2 * d1).cwiseAbs().maxCoeff(), 1e-12 * bunny.V.cwiseAbs().maxCoeff());
  options.smoothing_iterations = 0;  // no smoothing: no detail to add
  EXPECT_EQ(unsharp_mask(bunny.V, bunny.F, options).V, bunny.V);
}

TEST(Unsharp, BoundaryAndPinnedVerticesStayExactly) {
  const Mesh hemisphere = read_mesh(test::data_path("hemisphere.off"));
  const Topology topology = build_topology(hemisphere.F, hemisphere.num_vertices());
  UnsharpOptions options;
  options.weight = 1.0;
  options.constraints.pinned = {5, 100, 1000};
  const UnsharpResult result = unsharp_mask(hemisphere.V, hemisphere.F, options);
  Index boundary = 0;
  for (Index v = 0; v < hemisphere.num_vertices(); ++v) {
    if (topology.is_boundary_vertex[static_cast<std::size_t>(v)]) {
      ++boundary;
      EXPECT_EQ(result.V.row(v), hemisphere.V.row(v)) << v;
    }
  }
  for (const Index p : options.constraints.pinned) {
    ASSERT_FALSE(topology.is_boundary_vertex[static_cast<std::size_t>(p)]);
    EXPECT_EQ(result.V.row(p), hemisphere.V.row(p)) << p;
  }
  EXPECT_EQ(result.fixed_vertices, boundary + 3);
  EXPECT_GT((result.V - hemisphere.V).rowwise().norm().maxCoeff(), 0.0);

  options.constraints.fix_boundary = false;
  options.constraints.pinned.clear();
  const UnsharpResult free = unsharp_mask(hemisphere.V, hemisphere.F, options);
  EXPECT_EQ(free.fixed_vertices, 0);
  double boundary_motion = 0;
  for (const Index v : topology.boundary_loops.front()) boundary_motion += (free.V.row(v) - hemisphere.V.row(v)).norm();
  EXPECT_GT(boundary_motion, 0.0);
}

TEST(Unsharp, InvariantUnderRigidMotionAndUniformScale) {
  const Mesh head = read_mesh(test::data_path("max-planck-5k.obj"));
  const Eigen::Matrix3d rotation = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, -0.5).normalized()).toRotationMatrix();
  const Eigen::RowVector3d shift(12.5, -3.0, 40.0);
  const double scale = 3.7;
  const auto transform = [&](const Vertices& V) -> Vertices {
    return ((scale * V * rotation.transpose()).rowwise() + shift).eval();
  };
  UnsharpOptions options;
  options.weight = 0.8;
  const Vertices direct = transform(unsharp_mask(head.V, head.F, options).V);
  const Vertices moved = unsharp_mask(transform(head.V), head.F, options).V;
  const double size = transform(head.V).cwiseAbs().maxCoeff();
  EXPECT_LT((direct - moved).cwiseAbs().maxCoeff(), 1e-13 * size);
  // ... and the motion itself is not negligible.
  EXPECT_GT((moved - transform(head.V)).rowwise().norm().maxCoeff(), 1e-4 * size);
}

// Non-manifold input is smoothed as its manifold split (unsharp.h): the vertices of a manifold
// component keep exactly the result they have alone, the non-manifold ones are held bit for bit.
TEST(Unsharp, NonManifoldMeshIsSmoothedAsItsManifoldSplit) {
  const Mesh spot = read_mesh(test::data_path("spot.obj"));
  const Mesh bowtie = test::bowtie();
  Mesh both;
  both.V.resize(spot.num_vertices() + bowtie.num_vertices(), 3);
  both.V << spot.V, (bowtie.V.rowwise() + Eigen::RowVector3d(5, 0, 0));
  both.F.resize(spot.num_faces() + bowtie.num_faces(), 3);
  both.F << spot.F, (bowtie.F.array() + spot.num_vertices());
  const Topology topology = build_topology(both.F, both.num_vertices());
  ASSERT_FALSE(topology.is_manifold());
  const UnsharpResult result = unsharp_mask(both.V, both.F);
  EXPECT_EQ(result.V.topRows(spot.num_vertices()), unsharp_mask(spot.V, spot.F).V);
  ASSERT_FALSE(topology.non_manifold_vertices.empty());
  for (const Index v : topology.non_manifold_vertices) EXPECT_EQ(result.V.row(v), both.V.row(v)) << v;
  EXPECT_EQ(result.non_manifold.held_vertices, static_cast<Index>(topology.non_manifold_vertices.size()));
  EXPECT_GT(result.non_manifold.cut_edges + result.non_manifold.held_vertices, 0);
  // On a vertex-clustered bunny (113 non-manifold edges) the free vertices move.
  const Mesh bunny = read_mesh(test::data_path("bunny.off"));
  const Mesh clustered = test::vertex_clustered(bunny, 0.03 * bounding_box(bunny.V).diagonal());
  const Topology clustered_topology = build_topology(clustered.F, clustered.num_vertices());
  ASSERT_FALSE(clustered_topology.is_manifold());
  const UnsharpResult sharpened = unsharp_mask(clustered.V, clustered.F);
  for (const Index v : clustered_topology.non_manifold_vertices) ASSERT_EQ(sharpened.V.row(v), clustered.V.row(v)) << v;
  EXPECT_GT((sharpened.V - clustered.V).rowwise().norm().mean(), 1e-3 * bounding_box(bunny.V).diagonal());
}

TEST(Unsharp, BadInputIsRefused) {
  const Mesh bowtie = test::bowtie();
  try {
    UnsharpOptions strict;
    strict.refuse_non_manifold = true;
    unsharp_mask(bowtie.V, bowtie.F, strict);
    FAIL() << "non-manifold mesh accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("unsharp mask: the mesh is not manifold"), std::string::npos) << e.what();
  }
  const Mesh sphere = test::icosphere(1.0, 1);
  UnsharpOptions options;
  options.constraints.pinned = {sphere.num_vertices()};
  EXPECT_THROW(unsharp_mask(sphere.V, sphere.F, options), std::invalid_argument);
  options.constraints.pinned.clear();
  options.smoothing_iterations = -1;
  EXPECT_THROW(unsharp_mask(sphere.V, sphere.F, options), std::invalid_argument);
  options.smoothing_iterations = 1;
  options.weight = std::nan("");
  EXPECT_THROW(unsharp_mask(sphere.V, sphere.F, options), std::invalid_argument);
  EXPECT_THROW(unsharp_mask(Vertices(), Faces()), std::invalid_argument);
}

}  // namespace
}  // namespace vertexflow
