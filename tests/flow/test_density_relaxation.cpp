// The density passes of FlowOptions::density (flow.h): they equalise area times sizing density
// (so areas on a sphere, where the density is constant), raise the redistribution beyond the
// paper's flow on real meshes, including the vertex-clustered bunnies of issue 15, keep the
// flow's promises and invariances, and refuse options out of range.
#include "shapes.h"
#include "test_support.h"

#include "vertexflow/distance.h"
#include "vertexflow/flow.h"
#include "vertexflow/io.h"
#include "vertexflow/metrics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <string>

namespace vertexflow {
namespace {

FlowOptions with_passes(int passes) {
  FlowOptions options;
  options.density.passes = passes;
  return options;
}

// Coefficient of variation of the vertex areas (1 / vertex_density).
double area_variation(const Vertices& V, const Faces& F) {
  const Eigen::ArrayXd area = vertex_density(V, F).array().inverse();
  return std::sqrt((area - area.mean()).square().mean()) / area.mean();
}

// At exponent 0 the density is constant, and the passes equalise the vertex areas of a
// tangentially jittered icosphere (as CGAL's tangential relaxation would) far beyond what the
// paper's flow alone does; at the default exponent 2 they do so less, because the jitter, which
// leaves the vertices in the sphere's tangent planes, makes the curvature uneven.
TEST(DensityRelaxation, EqualisesTheAreasOfAJitteredSphere) {
  const Mesh sphere = test::noisy_scan(test::icosphere(1.0, 4), 0.0, 0.3, 7);
  const double input = area_variation(sphere.V, sphere.F);
  const FlowResult flow = vertex_flow(sphere.V, sphere.F);
  FlowOptions constant = with_passes(30);
  constant.density.exponent = 0;
  const FlowResult passes = vertex_flow(sphere.V, sphere.F, constant);
  test::expect_guard_promises_kept(sphere, passes.V, true, {}, 0.3, 0.5);
  const double after_flow = area_variation(flow.V, sphere.F), after_passes = area_variation(passes.V, sphere.F);
  std::cout << "[measured] jittered sphere: vertex-area CV " << input << " -> " << after_flow << " (flow), "
            << after_passes << " (30 passes)\n";
  const Mesh regular = test::icosphere(1.0, 4);
  const double unjittered = area_variation(regular.V, regular.F);
  std::cout << "[measured] the unjittered icosphere: " << unjittered << "\n";
  // Measured 0.159 -> 0.109 (flow) and 0.069 (passes): below the unjittered icosphere's own
  // 0.077, which its subdivision, not jitter, makes uneven.
  EXPECT_LT(after_passes, 0.75 * after_flow);
  EXPECT_LT(after_passes, unjittered);
}

// bunny_uniform: the passes add to the flow's redistribution and to its evening-out of the
// edge error (the paper's objective), keep every promise, and leave the vertices on the input.
TEST(DensityRelaxation, RaisesTheRedistributionOfBunnyUniform) {
  const Mesh bunny = read_mesh(test::data_path("bunny_uniform.off"));
  const FlowResult flow = vertex_flow(bunny.V, bunny.F);
  const FlowResult passes = vertex_flow(bunny.V, bunny.F, with_passes(10));
  test::expect_guard_promises_kept(bunny, passes.V, true, {}, 0.3, 0.5);
  const double flow_gain = test::redistribution_rho_change(bunny, flow.V).gain(),
               passes_gain = test::redistribution_rho_change(bunny, passes.V).gain();
  const double edge = passes.report.mean_edge_length;
  // The projection puts vertices on the Phong surface of the input (surface_projection.h), as
  // it does the flow's: their distance to the input's flat faces stays what the flow's is.
  SamplingOptions sampling;
  sampling.samples = 0;  // the vertices alone
  const double flow_off = one_sided_distance(flow.V, bunny.F, bunny.V, bunny.F, sampling).mean / edge;
  const double passes_off = one_sided_distance(passes.V, bunny.F, bunny.V, bunny.F, sampling).mean / edge;
  std::cout << "[measured] bunny_uniform: rho gain " << flow_gain << " (flow), " << passes_gain
            << " (10 passes); mean vertex distance to the input's faces " << flow_off << " (flow), " << passes_off
            << " (passes) edge lengths; " << passes.report.density_limited_vertices
            << " vertices limited by the passes' guard\n";
  EXPECT_GE(passes_gain, flow_gain + 0.08);  // measured +0.355 and +0.549
  EXPECT_LT(passes_off, 3 * flow_off + 1e-9);
}

// Issue 15: the vertex-clustered bunnies of FlowOnClusteredBunny (flow), where the paper's flow
// raises rho by 0.15-0.20 only: 30 passes raise it by at least 0.2, with the non-manifold
// vertices held and the promises kept. rho is that of the manifold split (the same surface) as
// in FlowOnClusteredBunny.
class DensityOnClusteredBunny : public ::testing::TestWithParam<double> {};

TEST_P(DensityOnClusteredBunny, RaisesRhoByAtLeastTwoTenths) {
  const Mesh mesh = test::clustered_bunny(GetParam());
  const Topology topology = build_topology(mesh.F, mesh.num_vertices());
  ASSERT_FALSE(topology.is_manifold());
  const FlowResult result = vertex_flow(mesh.V, mesh.F, topology, with_passes(30));
  test::expect_guard_promises_kept(mesh, result.V, true, {}, 0.3, 0.5);
  for (const Index v : topology.non_manifold_vertices) ASSERT_EQ(result.V.row(v), mesh.V.row(v)) << v;
  const double gain = test::redistribution_rho_change(mesh, result.V).gain();
  std::cout << "[measured] clustered bunny " << GetParam() << ": rho gain with 30 passes " << gain << "\n";
  // Measured +0.295, +0.297, +0.244 (the flow alone: +0.175, +0.191, +0.150).
  EXPECT_GE(gain, 0.2);
}

INSTANTIATE_TEST_SUITE_P(CellSizes, DensityOnClusteredBunny, ::testing::Values(0.015, 0.02, 0.03),
                         [](const auto& param_info) { return "cell_" + std::to_string(int(1000 * param_info.param)); });

// The same bytes for 1 and 2 threads (fandisk: creases, corners, a flat region). That crease
// vertices stay on their creases is FlowProjection.CreaseVerticesStayOnTheirCreasesAndCornersStay.
TEST(DensityRelaxation, DeterministicForAnyThreadCount) {
  const Mesh fandisk = read_mesh(test::data_path("fandisk.off"));
  const FlowResult one = test::with_threads(1, [&] { return vertex_flow(fandisk.V, fandisk.F, with_passes(10)); });
  const FlowResult two = test::with_threads(2, [&] { return vertex_flow(fandisk.V, fandisk.F, with_passes(10)); });
  EXPECT_EQ(one.V, two.V);
  const double moved =
      (one.V - vertex_flow(fandisk.V, fandisk.F).V).rowwise().norm().mean() / one.report.mean_edge_length;
  std::cout << "[measured] fandisk: the passes move the flow's result by " << moved << " edge lengths on average\n";
  EXPECT_GT(moved, 0.08);  // measured 0.233
}

// A rotated, translated and uniformly scaled input gives the same transform of the result.
TEST(DensityRelaxation, InvariantUnderSimilarity) {
  const Mesh bunny = read_mesh(test::data_path("bunny_uniform.off"));
  const FlowResult plain = vertex_flow(bunny.V, bunny.F, with_passes(10));
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, -2, 0.5).normalized()).toRotationMatrix();
  auto move = [&](const Vertices& X) -> Vertices {
    return ((3.5 * X * R.transpose()).rowwise() + Eigen::RowVector3d(4, -1, 2)).eval();
  };
  const FlowResult moved = vertex_flow(move(bunny.V), bunny.F, with_passes(10));
  const double difference = (moved.V - move(plain.V)).cwiseAbs().maxCoeff() / bounding_box(moved.V).diagonal();
  std::cout << "[measured] bunny_uniform with 10 passes, similarity: difference " << difference << "\n";
  EXPECT_LE(difference, 1e-6);
}

TEST(DensityRelaxation, RefusesOptionsOutOfRange) {
  const Mesh sphere = test::icosphere(1.0, 2);
  auto refused = [&](auto change) {
    FlowOptions options;
    change(options.density);
    EXPECT_THROW(vertex_flow(sphere.V, sphere.F, options), std::invalid_argument);
  };
  refused([](DensityRelaxation& d) { d.passes = -1; });
  refused([](DensityRelaxation& d) { d.passes = 1001; });
  refused([](DensityRelaxation& d) { d.exponent = -1; });
  refused([](DensityRelaxation& d) { d.exponent = std::nan(""); });
  refused([](DensityRelaxation& d) { d.epsilon = 0; });
  refused([](DensityRelaxation& d) { d.step = 0; });
  refused([](DensityRelaxation& d) { d.step = 1.5; });
  FlowOptions unprojected = with_passes(5);
  unprojected.project_to_input = false;
  EXPECT_THROW(vertex_flow(sphere.V, sphere.F, unprojected), std::invalid_argument);
}

// Issue 32 item 9: the exponent is bounded where the density stays finite. At 1e5 every density,
// (0.1 + |k1| + |k2|)^1e5, was 0 (|k1| + |k2| < 0.9 per mean edge length) or inf, which gave a
// vertex no centroid or a NaN one, without a word.
TEST(DensityRelaxation, TheExponentIsBoundedWhereTheDensityIsFinite) {
  const Mesh sphere = test::noisy_scan(test::icosphere(1.0, 3), 0.0, 0.3, 7);
  for (const double exponent : {1e5, 10.5}) {
    FlowOptions options = with_passes(3);
    options.density.exponent = exponent;
    try {
      vertex_flow(sphere.V, sphere.F, options);
      ADD_FAILURE() << "exponent " << exponent << " accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("density.exponent must be in [0, 10]"), std::string::npos) << e.what();
    }
  }
  // At the bound the passes still move the vertices beyond the flow's result.
  FlowOptions at_bound = with_passes(3);
  at_bound.density.exponent = DensityRelaxation::max_exponent;
  const double difference =
      (vertex_flow(sphere.V, sphere.F, at_bound).V - vertex_flow(sphere.V, sphere.F).V).rowwise().norm().maxCoeff();
  std::cout << "[measured] jittered sphere, 3 passes at exponent 10: largest difference from the flow " << difference
            << "\n";
  EXPECT_GT(difference, 0.0);
  // A density that underflows all the same (epsilon 1e-40 on the flat faces of a rounded cube:
  // 1e-400) is refused by name, not passed over.
  FlowOptions underflow = at_bound;
  underflow.density.epsilon = 1e-40;
  const Mesh cube = test::rounded_cube(1.0, 0.3, 6);
  try {
    vertex_flow(cube.V, cube.F, underflow);
    ADD_FAILURE() << "a density of 0 accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("sizing density"), std::string::npos) << e.what();
  }
}

// A free boundary (fix_boundary false) moves in the solve but not in the passes, whose
// centroids would pull it inwards: hemisphere.off's rim ends where the flow alone puts it.
TEST(DensityRelaxation, LeavesAFreeBoundaryWhereTheSolvePutIt) {
  const Mesh hemisphere = read_mesh(test::data_path("hemisphere.off"));
  const Topology topology = build_topology(hemisphere.F, hemisphere.num_vertices());
  FlowOptions free = with_passes(10);
  free.constraints.fix_boundary = false;
  const FlowResult passes = vertex_flow(hemisphere.V, hemisphere.F, free);
  free.density.passes = 0;
  const FlowResult flow = vertex_flow(hemisphere.V, hemisphere.F, free);
  Index rim = 0, rim_moved_by_solve = 0;
  for (Index v = 0; v < hemisphere.num_vertices(); ++v) {
    if (!topology.is_boundary_vertex[static_cast<std::size_t>(v)]) continue;
    ++rim;
    rim_moved_by_solve += flow.V.row(v) != hemisphere.V.row(v);
    EXPECT_EQ(passes.V.row(v), flow.V.row(v)) << "rim vertex " << v;
  }
  const double interior_moved = (passes.V - flow.V).rowwise().norm().sum() / passes.report.mean_edge_length;
  std::cout << "[measured] hemisphere, free boundary: " << rim << " rim vertices, " << rim_moved_by_solve
            << " moved by the solve; the passes move the rest by " << interior_moved << " edge lengths in all\n";
  EXPECT_GT(rim_moved_by_solve, 0);  // the boundary is free
  EXPECT_GT(interior_moved, 20.0);   // measured 223 over the hemisphere's interior
}

}  // namespace
}  // namespace vertexflow
