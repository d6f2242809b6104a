// Garland-Heckbert simplification: the face budget, topology, exact boundaries, geometric error
// on a sphere and on planes, refusal of meshes a halfedge structure cannot hold.
#include "bench_support.h"
#include "boundary_points.h"
#include "shapes.h"
#include "test_support.h"

#include "vertexflow/flow.h"
#include "vertexflow/io.h"
#include "vertexflow/lod.h"
#include "vertexflow/quality.h"
#include "vertexflow/simplify.h"
#include "vertexflow/topology.h"

#include <gtest/gtest.h>

#include <array>
#include <iostream>
#include <set>

namespace vertexflow {
namespace {

using test::boundary_points;
using test::Point;

// Every test runs for both methods (simplify.h): they share the quadrics and the contract.
class Simplify : public ::testing::TestWithParam<SimplifyMethod> {};

INSTANTIATE_TEST_SUITE_P(Methods, Simplify, ::testing::Values(SimplifyMethod::Cgal, SimplifyMethod::Native),
                         [](const ::testing::TestParamInfo<SimplifyMethod>& param) {
                           return simplify_method_name(param.param);
                         });

TEST_P(Simplify, HitsTheFaceBudgetWithinOneFace) {
  const Mesh spot = read_mesh(test::data_path("spot.obj"));
  for (const Index target : {4000, 1001, 1000, 200}) {
    SimplifyOptions options;
    options.method = GetParam();
    options.target_faces = target;
    const SimplifyResult result = simplify(spot.V, spot.F, options);
    EXPECT_GE(result.mesh.num_faces(), target);
    EXPECT_LE(result.mesh.num_faces(), target + 1);
    EXPECT_EQ(result.report.output_faces, result.mesh.num_faces());
    EXPECT_EQ(result.report.input_faces, spot.num_faces());
    EXPECT_TRUE(result.report.reached_target);
    // A closed mesh loses one vertex and two faces per collapse.
    EXPECT_EQ(result.report.collapses, spot.num_vertices() - result.mesh.num_vertices());
    EXPECT_EQ(2 * result.report.collapses, spot.num_faces() - result.mesh.num_faces());
    test::expect_same_topology(spot, result.mesh);
  }
  SimplifyOptions ratio;
  ratio.method = GetParam();
  ratio.target_ratio = 0.25;
  const SimplifyResult quarter = simplify(spot.V, spot.F, ratio);
  EXPECT_EQ(quarter.report.target_faces, 1464);  // round(0.25 * 5856)
  EXPECT_LE(quarter.mesh.num_faces() - 1464, 1);
}

TEST_P(Simplify, KeepsGenusAndComponents) {
  for (const char* name : {"fertility.off", "torus.obj", "suzanne.obj"}) {
    const Mesh mesh = read_mesh(test::data_path(name));
    SimplifyOptions options;
    options.method = GetParam();
    options.target_ratio = 0.2;
    const SimplifyResult result = simplify(mesh.V, mesh.F, options);
    SCOPED_TRACE(name);
    test::expect_same_topology(mesh, result.mesh);
    EXPECT_LE(result.mesh.num_faces(), result.report.target_faces + 1);
  }
}

TEST_P(Simplify, BoundaryLoopsKeepEveryVertexExactly) {
  for (const char* name : {"hemisphere.off", "camelhead.off"}) {
    SCOPED_TRACE(name);
    const Mesh mesh = read_mesh(test::data_path(name));
    SimplifyOptions options;
    options.method = GetParam();
    options.target_ratio = 0.15;
    const SimplifyResult result = simplify(mesh.V, mesh.F, options);
    const std::set<Point> before = boundary_points(mesh);
    EXPECT_EQ(boundary_points(result.mesh), before);  // same positions, bit for bit, none lost
    // The interior still collapsed down to the budget.
    EXPECT_LE(result.mesh.num_faces(), result.report.target_faces + 1);
    test::expect_same_topology(mesh, result.mesh);
  }
}

// The quadric of a sphere patch pulls the merged vertex slightly outside the sphere: for planes
// tangent at angles phi from the vertex's direction the optimum is at R sum(cos) / sum(cos^2)
// ~ R (1 + mean(phi^2) / 2), and phi is at most about the output's longest edge over R. Inner
// faces cut chords, at most l^2 / (8 R) inside. So |r - R| <= l_max^2 / (2 R) with room.
TEST_P(Simplify, SphereStaysCloseToTheSphere) {
  const Mesh sphere = read_mesh(test::data_path("sphere.off"));  // unit sphere, 32k faces
  SimplifyOptions options;
  options.method = GetParam();
  options.target_faces = 2000;
  const SimplifyResult result = simplify(sphere.V, sphere.F, options);
  const Topology topology = build_topology(result.mesh.F, result.mesh.num_vertices());
  double longest = 0;
  for (Index e = 0; e < topology.num_edges(); ++e)
    longest =
        std::max(longest, (result.mesh.V.row(topology.edges(e, 0)) - result.mesh.V.row(topology.edges(e, 1))).norm());
  const Eigen::VectorXd radius = result.mesh.V.rowwise().norm();
  const double deviation = (radius.array() - 1.0).abs().maxCoeff();
  std::cout << "sphere: max radial deviation " << deviation << ", longest edge " << longest << "\n";
  EXPECT_LT(deviation, longest * longest / 2);
  EXPECT_LT(deviation, 0.01);  // in absolute terms: 1% of the radius
  test::expect_same_topology(sphere, result.mesh);
}

// Collapses inside a plane cost nothing, so a flat square grid collapses down to (almost) the
// fewest triangles its boundary allows. With the boundary kept (b vertices, all stay) every
// interior vertex but at most one goes: the last one's only collapses are onto boundary
// vertices, and a fan from a vertex of the square's sides has degenerate triangles, which CGAL
// refuses. With a free boundary only the four corners remain: two triangles.
TEST_P(Simplify, PlanesCollapseToTheirBoundaryWithoutError) {
  Mesh grid = test::saddle(1.0, 20);
  grid.V.col(2).setZero();
  const Topology topology = build_topology(grid.F, grid.num_vertices());
  const Index boundary = static_cast<Index>(topology.boundary_loops.front().size());
  ASSERT_EQ(boundary, 80);
  ASSERT_EQ(grid.num_vertices(), 441);

  SimplifyOptions options;

  options.method = GetParam();
  options.target_faces = 1;
  const SimplifyResult kept = simplify(grid.V, grid.F, options);
  EXPECT_LE(kept.mesh.num_vertices(), boundary + 1);
  EXPECT_EQ(boundary_points(kept.mesh), boundary_points(grid));
  EXPECT_LE(kept.mesh.num_faces(), boundary);  // disk: F = 2 V - b - 2
  EXPECT_FALSE(kept.report.reached_target);
  EXPECT_EQ(kept.mesh.V.col(2).cwiseAbs().maxCoeff(), 0.0);
  double area = 0;
  for (Index f = 0; f < kept.mesh.num_faces(); ++f) {
    EXPECT_GT(face_normal(kept.mesh.V, kept.mesh.F, f).z(), 0.0) << "face " << f << " folded";
    area += face_area(kept.mesh.V, kept.mesh.F, f);
  }
  EXPECT_NEAR(area, 4.0, 1e-12);

  options.keep_boundary = false;
  const SimplifyResult free = simplify(grid.V, grid.F, options);
  EXPECT_EQ(free.mesh.num_faces(), 2);
  ASSERT_EQ(free.mesh.num_vertices(), 4);
  for (Index v = 0; v < 4; ++v) {
    EXPECT_NEAR(std::abs(free.mesh.V(v, 0)), 1.0, 1e-12);
    EXPECT_NEAR(std::abs(free.mesh.V(v, 1)), 1.0, 1e-12);
    EXPECT_NEAR(free.mesh.V(v, 2), 0.0, 1e-12);
  }
}

// Flat subdivisions (whole rows of vertices on one line; QEM's collapses there cost nothing): no
// level has a face that mesh.h calls degenerate, which read_mesh would remove, leaving holes.
// Measured before the native collapse refused them: 2 such faces at 5% of max-planck-5k cut
// 1-to-25 (none on the sphere, none with CGAL's collapse; the lattice's vertex order decides
// QEM's ties, and with this one the 1-to-9 cut had none).
TEST_P(Simplify, FlatSubdivisionsLeaveNoDegenerateFace) {
  for (const Mesh& mesh : {bench::subdivide_uniform(test::icosphere(1.0, 2), 5),
                           bench::subdivide_uniform(read_mesh(test::data_path("max-planck-5k.obj")), 5)}) {
    for (const double ratio : {0.5, 0.2, 0.05}) {
      SimplifyOptions options;
      options.method = GetParam();
      options.target_faces = static_cast<Index>(ratio * static_cast<double>(mesh.num_faces()));
      const SimplifyResult r = simplify(mesh.V, mesh.F, options);
      SCOPED_TRACE(::testing::Message() << mesh.num_faces() << " faces to " << r.mesh.num_faces());
      EXPECT_EQ(degenerate_faces(r.mesh.V, r.mesh.F).size(), 0u);
    }
  }
}

TEST_P(Simplify, BudgetAtOrAboveTheInputChangesNothing) {
  const Mesh torus = read_mesh(test::data_path("torus.obj"));
  SimplifyOptions options;
  options.method = GetParam();
  options.target_faces = torus.num_faces();
  const SimplifyResult result = simplify(torus.V, torus.F, options);
  EXPECT_EQ(result.mesh.V, torus.V);
  EXPECT_EQ(result.mesh.F, torus.F);
  EXPECT_EQ(result.report.collapses, 0);
}

// Non-manifold and inconsistently oriented input is simplified through its manifold split: the
// result is clean, and the flow takes it with refuse_non_manifold.
TEST_P(Simplify, NonManifoldAndMisorientedInputGiveACleanMesh) {
  Mesh flipped = test::icosphere(1.0, 2);
  flipped.F.row(3) = flipped.F.row(3).reverse().eval();
  SimplifyOptions half;
  half.method = GetParam();
  half.target_ratio = 0.5;
  const SimplifyResult oriented = simplify(flipped.V, flipped.F, half);
  test::expect_clean_surface(oriented.mesh);
  EXPECT_EQ(oriented.report.repairs.input_split.reversed_faces, 1);
  EXPECT_EQ(oriented.report.output_faces, 160);

  const Mesh scan = test::with_random_faces_removed(read_mesh(test::data_path("bunny.off")), 2000, 5);
  const Topology topology = build_topology(scan.F, scan.num_vertices());
  ASSERT_GE(topology.boundary_loops.size(), 100u);
  ASSERT_FALSE(topology.is_manifold());
  SimplifyOptions options;
  options.method = GetParam();
  options.target_faces = 12000;
  const SimplifyResult result = simplify(scan.V, scan.F, options);
  std::cout << "[measured] bunny.off minus 2000 faces -> " << result.report.output_faces << " faces; split "
            << result.report.repairs.input_split.held_vertices << ", removed degenerate "
            << result.report.repairs.removed_degenerate_faces << ", duplicated "
            << result.report.repairs.duplicated_vertices << "\n";
  test::expect_clean_surface(result.mesh);
  EXPECT_TRUE(result.report.reached_target);
  EXPECT_GT(result.report.repairs.input_split.held_vertices, 100);
  FlowOptions strict;
  strict.refuse_non_manifold = true;
  const FlowResult flowed = vertex_flow(result.mesh.V, result.mesh.F, strict);
  EXPECT_TRUE(flipped_faces(result.mesh.V, flowed.V, result.mesh.F).empty());
}

TEST_P(Simplify, RefusesBadOptions) {
  const Mesh sphere = test::icosphere(1.0, 1);
  SimplifyOptions options;
  options.method = GetParam();
  options.target_ratio = 0;
  EXPECT_THROW(simplify(sphere.V, sphere.F, options), std::invalid_argument);
  options.target_ratio = 1.5;
  EXPECT_THROW(simplify(sphere.V, sphere.F, options), std::invalid_argument);
  options.target_faces = -3;
  EXPECT_THROW(simplify(sphere.V, sphere.F, options), std::invalid_argument);
  EXPECT_THROW(simplify(Vertices(), Faces()), std::invalid_argument);
}

// The native collapse shares CGAL's placement and weights its quadrics by area, so its meshes
// are at least as close to the dense surface. Measured on bunny.off (two-sided mean distance,
// lod.h's measurement), native over CGAL: 0.974 at 10%, 0.953 at 2% (bench/lod_peers: 0.76-1.00
// on five more meshes, averaged over 50-2%, docs/lod.md). A collapse in any other order, or a
// worse placement, measures 1.3-1.7 times CGAL's (meshoptimizer, which keeps input positions:
// 1.59 and 1.63 here).
TEST(SimplifyNative, IsAtLeastAsCloseToTheDenseMeshAsCgal) {
  const Mesh bunny = read_mesh(test::data_path("bunny.off"));
  const ReferenceSurface dense(bunny.V, bunny.F);
  for (const Index target : {6967, 1393}) {
    SimplifyOptions options;
    options.target_faces = target;
    const double cgal = lod_distance(simplify(bunny.V, bunny.F, options).mesh, dense).mean;
    options.method = SimplifyMethod::Native;
    const SimplifyResult native = simplify(bunny.V, bunny.F, options);
    const double ours = lod_distance(native.mesh, dense).mean;
    std::cout << "[measured] bunny.off to " << target << " faces: mean distance native / CGAL " << ours / cgal << "\n";
    EXPECT_LE(native.mesh.num_faces(), target + 1);
    EXPECT_LT(ours, 0.995 * cgal);
    EXPECT_GT(ours, 0.85 * cgal);  // not better by much either: the same planes, other weights
  }
}

// Scaling by a power of two is exact in floating point, and nothing in the collapse depends on
// the mesh's size (unit normals, relative thresholds): the same collapses, at twice the places.
TEST(SimplifyNative, UniformScaleGivesTheSameCollapses) {
  const Mesh mesh = read_mesh(test::data_path("camelhead.off"));  // with a boundary loop
  SimplifyOptions options;
  options.method = SimplifyMethod::Native;
  options.target_ratio = 0.1;
  for (const bool keep_boundary : {true, false}) {
    options.keep_boundary = keep_boundary;
    const SimplifyResult plain = simplify(mesh.V, mesh.F, options);
    const Vertices doubled = 2 * mesh.V;
    const SimplifyResult scaled = simplify(doubled, mesh.F, options);
    ASSERT_LT(plain.mesh.num_faces(), mesh.num_faces() / 5);
    EXPECT_EQ(scaled.mesh.F, plain.mesh.F);
    EXPECT_EQ(scaled.mesh.V, (2 * plain.mesh.V).eval());
  }
}

// Serial collapses on a topology built in parallel: the same bytes for any thread count.
TEST(SimplifyNative, SameBytesForOneAndTwoThreads) {
  const Mesh mesh = read_mesh(test::data_path("horse-48k.ply"));
  SimplifyOptions options;
  options.method = SimplifyMethod::Native;
  options.target_faces = 5000;
  const Mesh one = test::with_threads(1, [&] { return simplify(mesh.V, mesh.F, options).mesh; });
  const Mesh two = test::with_threads(2, [&] { return simplify(mesh.V, mesh.F, options).mesh; });
  EXPECT_EQ(one.V, two.V);
  EXPECT_EQ(one.F, two.F);
}

}  // namespace
}  // namespace vertexflow
