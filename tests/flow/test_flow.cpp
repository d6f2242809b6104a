// vertex_flow end to end on real meshes: the guarantees (no flips, no degenerate faces, fixed
// and pinned vertices stay), invariance under similarity transforms, the lambda knob, volume.
#include "shapes.h"
#include "test_support.h"

#include "vertexflow/compare.h"
#include "vertexflow/distance.h"
#include "vertexflow/features.h"
#include "vertexflow/flow.h"
#include "vertexflow/io.h"
#include "vertexflow/manifold_split.h"
#include "vertexflow/quality.h"

#include "guard/guard.h"
#include "surface_projection.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <future>
#include <initializer_list>
#include <iostream>
#include <limits>
#include <random>
#include <utility>
#include <vector>

namespace vertexflow {
namespace {

double mean_displacement(const Vertices& a, const Vertices& b) {
  return (a - b).rowwise().norm().mean();
}

// The flow moved the vertices of `mesh` by at least `min_edge_lengths` on average: a test that
// uses this cannot pass with the flow replaced by the identity.
void expect_moved(const Mesh& mesh, const Vertices& X, double min_edge_lengths) {
  const double edge = mean_edge_length(mesh.V, build_topology(mesh.F, mesh.num_vertices()));
  EXPECT_GE(mean_displacement(X, mesh.V) / edge, min_edge_lengths) << "the flow did not move the vertices";
}

// What one flow at the given options must do to one mesh, beyond the guarantees that hold for
// every mesh. Bounds are set from the values measured at the defaults (noted with each case) with
// a margin of 2-3x, so that a flow that moves nothing, moves too far or leaves the surface fails.
struct FlowExpectation {
  const char* file;
  /// Mean displacement in input mean edge lengths is at least this; 0 where nothing may move
  /// (every vertex a corner, or a mesh whose vertices are all alike), which is then asserted.
  double min_displacement;
  /// Mean one-sided distance from the result's surface to the input's, in mean edge lengths.
  double max_drift;
  /// |volume after - volume before| / |volume before| (closed meshes only).
  double max_volume_change;
  /// Vertex redistribution rho (docs/metrics.md) after minus before is at least this.
  double min_rho_gain;
  /// Fraction of the vertices whose displacement the guard shortened.
  double max_limited_fraction;
};

std::ostream& operator<<(std::ostream& out, const FlowExpectation& e) {
  return out << e.file;
}

// The guarantees of flow.h on any mesh, at any options: no flipped or degenerate face, fixed
// vertices bit for bit where they were, every face's radius ratio at or above the floor
// FlowOptions::min_quality states (exactly: up to the rounding of mapping the normalised result
// back).
void expect_promises_kept(const Mesh& mesh, const FlowResult& result, const FlowOptions& options = {}) {
  test::expect_guard_promises_kept(mesh, result.V, options.constraints.fix_boundary, options.constraints.pinned,
                                   options.guard.min_quality, options.guard.sliver_floor);
}

// The promises, then the effect one flow at `options` must have on `mesh` (expectation).
void expect_flow_effect(const Mesh& mesh, const FlowResult& result, const FlowExpectation& expected,
                        const FlowOptions& options = {}) {
  expect_promises_kept(mesh, result, options);
  const double edge = result.report.mean_edge_length;
  const double moved = mean_displacement(result.V, mesh.V) / edge;
  const double limited = static_cast<double>(result.report.limited_vertices) / static_cast<double>(mesh.num_vertices());
  // Drift: area samples, exact distances (distance.h).
  SamplingOptions sampling;
  sampling.samples = 50000;
  const double drift = one_sided_distance(result.V, mesh.F, mesh.V, mesh.F, sampling).mean / edge;
  CompareOptions compare;
  compare.sampling.samples = 1000;  // only rho is used
  Mesh out = mesh;
  out.V = result.V;
  const MeshComparison c = compare_meshes(out, mesh, nullptr, compare);
  const double rho_gain = c.redistribution_rho_result - c.redistribution_rho_input;
  const Topology topology = build_topology(mesh.F, mesh.num_vertices());
  const double volume_change =
      topology.is_closed() ? std::abs(signed_volume(result.V, mesh.F) / signed_volume(mesh.V, mesh.F) - 1.0) : 0.0;
  std::cout << "[measured] " << expected.file << ": displacement " << moved << ", drift " << drift << ", volume "
            << volume_change << ", rho " << c.redistribution_rho_input << " -> " << c.redistribution_rho_result
            << ", limited " << limited << ", flipped before guard " << result.report.flipped_before_guard
            << ", low quality before guard " << result.report.low_quality_before_guard << "\n";
  if (expected.min_displacement > 0) {
    EXPECT_GE(moved, expected.min_displacement);
  } else {
    EXPECT_LE((result.V - mesh.V).cwiseAbs().maxCoeff(), 1e-9 * edge) << "nothing may move";
  }
  EXPECT_LE(drift, expected.max_drift);
  EXPECT_LE(volume_change, expected.max_volume_change);
  EXPECT_GE(rho_gain, expected.min_rho_gain) << c.redistribution_rho_input << " -> " << c.redistribution_rho_result;
  EXPECT_LE(limited, expected.max_limited_fraction);
}

class FlowOnMesh : public ::testing::TestWithParam<FlowExpectation> {};

TEST_P(FlowOnMesh, KeepsItsPromisesAndMovesTheVertices) {
  const Mesh mesh = read_mesh(test::data_path(GetParam().file));
  expect_flow_effect(mesh, vertex_flow(mesh.V, mesh.F), GetParam());
}

// Measured at the defaults (displacement, drift, volume change, rho gain, limited fraction) in the
// comment of each row; the bounds are 2.5x those (limited: 2x; a gain below 0.02 may fall by
// 1.5x its size or 0.006). rho falls a little on meshes already graded by curvature (QEM
// decimations, adaptive remeshes: the paper's energy evens their edge errors but cannot add
// grading, docs/redistribution.md) and is noise on surfaces of constant curvature.
INSTANTIATE_TEST_SUITE_P(Data, FlowOnMesh,
                         ::testing::Values(
                             // 0.14, 0.0097, 0.00021, +0.355, 0; near-uniform scan
                             FlowExpectation{"bunny_uniform.off", 0.056, 0.024, 0.00053, 0.14, 0.002},
                             // 0.786, 0.0015, 0.00013, +0.56, 0.00402; near-uniform CAD part
                             FlowExpectation{"fandisk.off", 0.31, 0.0038, 0.00033, 0.22, 0.008},
                             // 0.287, 0.014, 0.0015, -0.0005, 0.0156; QEM-graded
                             FlowExpectation{"max-planck-5k.obj", 0.11, 0.036, 0.0037, -0.0065, 0.031},
                             // 0.0288, 0.00057, open, -0.0341, 0; constant curvature
                             FlowExpectation{"hemisphere.off", 0.012, 0.0014, 0, -0.085, 0.002},
                             // 0.263, 0.0049, open, +0.061, 0.14
                             FlowExpectation{"camelhead.off", 0.11, 0.012, 0, 0.024, 0.28},
                             // 0.273, 0.015, 0.0033, +0.12, 0.0539
                             FlowExpectation{"spot.obj", 0.11, 0.037, 0.0083, 0.048, 0.11},
                             // 0.00364, 0.00012, 5.5e-05, +0.0036, 0; graded along the tube
                             FlowExpectation{"torus.obj", 0.0015, 0.0003, 0.00014, -0.0024, 0.002},
                             // 0.265, 0.013, 0.0035, -0.01, 0.0218; graded
                             FlowExpectation{"fertility.off", 0.11, 0.031, 0.0088, -0.025, 0.044},
                             // 0.304, 0.018, 0.0018, -0.0062, 0.013; graded
                             FlowExpectation{"rocker-arm.obj", 0.12, 0.044, 0.0044, -0.015, 0.026},
                             // 0.206, 0.012, 0.00031, +0.049, 0.00272
                             FlowExpectation{"bunny_adaptive.off", 0.082, 0.03, 0.00077, 0.02, 0.0054},
                             // 0.199, 0.009, 0.00042, +0.0047, 0.012
                             FlowExpectation{"amo_adaptive.off", 0.08, 0.022, 0.0011, -0.0024, 0.024},
                             // 0.0291, 0.0015, 0.00046, +0.0119, 0; constant curvature
                             FlowExpectation{"sphere_low.off", 0.012, 0.0036, 0.0011, -0.006, 0.002},
                             // 0.145, 0.034, open, +0.037, 0.073
                             FlowExpectation{"suzanne.obj", 0.058, 0.084, 0, 0.015, 0.15},
                             // 0.375, 0.0062, 0.0014, +0.29, 0.00522
                             FlowExpectation{"fandisk_quads.off", 0.15, 0.015, 0.0036, 0.12, 0.01},
                             // Every vertex a corner of its chamfers; all twelve vertices alike: nothing may move.
                             FlowExpectation{"chamfer-cube.off", 0, 1e-12, 1e-12, 0, 0},
                             FlowExpectation{"icosahedron_binary.stl", 0, 1e-12, 1e-12, 0, 0}),
                         [](const auto& param_info) { return test::test_name(param_info.param.file); });

// The quality promise exactly as flow.h states it, on every bundled mesh, at the default floor
// and at a higher one.
class FlowQualityPromise : public ::testing::TestWithParam<const char*> {};

TEST_P(FlowQualityPromise, EveryFaceEndsAtOrAboveItsFloor) {
  const Mesh mesh = read_mesh(test::data_path(GetParam()));
  for (const double min_quality : {0.3, 0.5}) {
    SCOPED_TRACE(min_quality);
    FlowOptions options;
    options.guard.min_quality = min_quality;
    const FlowResult result = vertex_flow(mesh.V, mesh.F, options);
    std::cout << "[measured] " << GetParam() << " min_quality " << min_quality << ": low quality before guard "
              << result.report.low_quality_before_guard << ", limited " << result.report.limited_vertices << "\n";
    expect_promises_kept(mesh, result, options);
    // Every mesh but the two where nothing may move (FlowOnMesh) moves: measured minimum
    // 0.00037 mean edge lengths on sphere.off (constant curvature: nothing to move towards),
    // then torus.obj 0.0036; the others 0.029 or more.
    const std::string name = GetParam();
    if (name.find("icosahedron") == std::string::npos && name != "chamfer-cube.off")
      expect_moved(mesh, result.V, 1.5e-4);
  }
}

INSTANTIATE_TEST_SUITE_P(Data, FlowQualityPromise,
                         ::testing::Values("amo.off", "amo_adaptive.off", "armadillo-43k.obj", "bunny.off",
                                           "bunny_adaptive.off", "bunny_uniform.off", "camelhead.off",
                                           "chamfer-cube.off", "fandisk.off", "fandisk_quads.off", "fertility.off",
                                           "hemisphere.off", "horse-48k.ply", "icosahedron_ascii.stl",
                                           "icosahedron_binary.stl", "max-planck-5k.obj", "rocker-arm.obj",
                                           "sphere.off", "sphere_low.off", "spot.obj", "suzanne.obj", "torus.obj"),
                         [](const auto& param_info) { return test::test_name(param_info.param); });

// Issue 4's redistribution and edge-error bars at the default options, measured as the report
// measures them (compare_meshes: input curvature at each vertex's closest point on the input).
// bunny_uniform and fandisk start near-uniform: rho rises by >= 0.2 (measured +0.355 and
// +0.471) and the edge-error CV falls by >= 10% (11.8% and 13.0%). max-planck-5k is a QEM
// decimation, already graded (rho 0.712): the paper's energy evens its edge errors out (CV
// -11.3%) but cannot raise rho much (docs/redistribution.md); it must not lower it.
struct RedistributionCase {
  const char* file;
  double min_rho_gain;
};

class FlowRedistribution : public ::testing::TestWithParam<RedistributionCase> {};

TEST_P(FlowRedistribution, MeetsTheRedistributionAndEdgeErrorBars) {
  const Mesh mesh = read_mesh(test::data_path(GetParam().file));
  Mesh result = mesh;
  result.V = vertex_flow(mesh.V, mesh.F).V;
  CompareOptions options;
  options.sampling.samples = 1000;  // distances are not what this test is about
  const MeshComparison c = compare_meshes(result, mesh, nullptr, options);
  EXPECT_GE(c.redistribution_rho_result - c.redistribution_rho_input, GetParam().min_rho_gain)
      << c.redistribution_rho_input << " -> " << c.redistribution_rho_result;
  EXPECT_LE(c.edge_error_result.coefficient_of_variation, 0.9 * c.edge_error_input.coefficient_of_variation);
}

INSTANTIATE_TEST_SUITE_P(Data, FlowRedistribution,
                         ::testing::Values(RedistributionCase{"bunny_uniform.off", 0.2},
                                           RedistributionCase{"fandisk.off", 0.2},
                                           RedistributionCase{"max-planck-5k.obj", -0.01}),
                         [](const auto& param_info) { return test::test_name(param_info.param.file); });

// Hard cases (issue 4): an unguarded solve flips faces on each; the guard repairs them without
// freezing the mesh.
void expect_guard_had_work(const FlowResult& result) {
  EXPECT_GT(result.report.flipped_before_guard, 0) << "the case is meant to make the unguarded solve flip faces";
}

TEST(FlowHardCases, ThinPerforatedPlateOfGenus16) {
  const Mesh plate = test::perforated_plate(4, 4, 0.1, true);
  const Topology topology = build_topology(plate.F, plate.num_vertices());
  ASSERT_TRUE(topology.is_manifold());
  ASSERT_EQ(topology.genus(), 16);
  const FlowResult result = vertex_flow(plate.V, plate.F);
  // At the defaults the projected solve leaves no bad face here (measured: 0 flipped, 0 below
  // the floor); at the strong end of lambda (0.2) it flips 12 faces, which the guard repairs.
  // Measured (as FlowOnMesh): defaults 0.438, 0 (flat faces: rounding), 0, +0.040, 0; lambda
  // 0.2: 0.488, 0, 0, +0.0094, 0.0049.
  expect_flow_effect(plate, result, {"perforated plate", 0.18, 1e-12, 1e-12, 0.016, 0.002});
  FlowOptions strong;
  strong.weights.lambda = 0.2;
  const FlowResult strong_result = vertex_flow(plate.V, plate.F, strong);
  expect_guard_had_work(strong_result);
  expect_flow_effect(plate, strong_result, {"perforated plate, lambda 0.2", 0.2, 1e-12, 1e-12, -0.0047, 0.0098},
                     strong);
  // The plate is 0.1 thick with edges of 0.25: no vertex ends nearer the opposite face than its
  // own, with the rims' creases (default) and without them (only the projection's walk).
  FlowOptions no_creases;
  no_creases.feature_angle = 180;
  const FlowResult smooth = vertex_flow(plate.V, plate.F, no_creases);
  expect_promises_kept(plate, smooth, no_creases);
  for (const Vertices* X : {&result.V, &smooth.V}) {
    for (Index v = 0; v < plate.num_vertices(); ++v)
      ASSERT_EQ(plate.V(v, 2) > 0.05, (*X)(v, 2) > 0.05) << "vertex " << v << " went through the plate";
  }
  EXPECT_GT(mean_displacement(smooth.V, plate.V), 0.01 * result.report.mean_edge_length);
}

TEST(FlowHardCases, OpenPlateWithHolesKeepsItsBoundaryLoops) {
  const Mesh plate = test::perforated_plate(3, 4, 0.25, false);
  const Topology topology = build_topology(plate.F, plate.num_vertices());
  ASSERT_TRUE(topology.is_manifold());
  ASSERT_EQ(topology.boundary_loops.size(), 10u);  // 9 holes and the outer rim
  const FlowResult result = vertex_flow(plate.V, plate.F);
  expect_guard_had_work(result);  // measured: 80 flipped
  // Measured: 0.361, 0 (flat faces), open, +0.042, 0.169.
  expect_flow_effect(plate, result, {"open plate", 0.14, 1e-12, 0, 0.017, 0.34});
}

// Issue 15's sliver-heavy thin shape: genus 121, 0.15 thick, cells cut into 8 jittered strips,
// so that most faces start below 0.3 and many flip under any large move. The guard rule of
// flow.h lets vertices move where the worst face they touch does not get worse (with slivers
// allowed to fall to half their quality); the previous rule (no face below its own input
// quality) shortened 89% of the vertices and moved them by 0.000 edge lengths, rho +0.00.
// F_sliver (flow_energy.h) keeps the solve's moves short of the slivers' altitudes, so that
// the guard shortens few of them: 17.5% of the vertices (55% without it).
TEST(FlowHardCases, SliverPlateOfGenus121Moves) {
  const Mesh plate = test::sliver_plate(11, 8, 0.15, 0.4, 1);
  const Topology topology = build_topology(plate.F, plate.num_vertices());
  ASSERT_TRUE(topology.is_manifold());
  ASSERT_EQ(topology.genus(), 121);
  const Eigen::VectorXd q = triangle_quality(plate.V, plate.F);
  ASSERT_GT((q.array() < 0.3).count(), plate.num_faces() * 6 / 10);  // measured 63%
  const FlowResult result = vertex_flow(plate.V, plate.F);
  expect_guard_had_work(result);
  // Measured: 0.126, 0 (flat faces), 0, +0.131 (0.426 -> 0.557), 0.175 (294 flipped, 2202 low
  // quality before the guard). rho and limited: the bars, +0.1 and 20%.
  expect_flow_effect(plate, result, {"sliver plate", 0.05, 1e-12, 1e-12, 0.1, 0.20});
  // Without F_sliver the guard does the work: measured 0.547 limited, 4013 flipped, rho +0.22.
  FlowOptions guard_alone;
  guard_alone.weights.sliver = 0;
  const FlowResult unstiffened = vertex_flow(plate.V, plate.F, guard_alone);
  expect_promises_kept(plate, unstiffened, guard_alone);
  EXPECT_GT(unstiffened.report.limited_vertices, 2 * result.report.limited_vertices);
  EXPECT_GT(unstiffened.report.flipped_before_guard, 5 * result.report.flipped_before_guard);
  // The rule's two knobs do what flow.h says: sliver_floor 1 (slivers no worse than the worst
  // face around them at the input) moves less; min_quality 0 (flips only, and no slivers for
  // F_sliver) moves more.
  FlowOptions strict_slivers;
  strict_slivers.guard.sliver_floor = 1;
  const FlowResult strict = vertex_flow(plate.V, plate.F, strict_slivers);
  expect_promises_kept(plate, strict, strict_slivers);
  FlowOptions flips_only;
  flips_only.guard.min_quality = 0;
  const FlowResult loose = vertex_flow(plate.V, plate.F, flips_only);
  expect_promises_kept(plate, loose, flips_only);
  EXPECT_LT(mean_displacement(strict.V, plate.V), mean_displacement(result.V, plate.V));
  EXPECT_GT(mean_displacement(loose.V, plate.V), mean_displacement(result.V, plate.V));
}

// F_sliver acts on slivers only: a mesh without faces below min_quality flows to the same bytes
// with and without it.
TEST(FlowHardCases, SliverTermIsZeroWithoutSlivers) {
  const Mesh mesh = read_mesh(test::data_path("bunny_uniform.off"));
  ASSERT_EQ((triangle_quality(mesh.V, mesh.F).array() < FlowOptions{}.guard.min_quality).count(), 0);
  FlowOptions without;
  without.weights.sliver = 0;
  EXPECT_EQ(vertex_flow(mesh.V, mesh.F).V, vertex_flow(mesh.V, mesh.F, without).V);
}

TEST(FlowHardCases, NoisyScanWithSlivers) {
  const Mesh scan = test::noisy_scan(read_mesh(test::data_path("bunny_uniform.off")), 0.15, 0.6, 7);
  const Eigen::VectorXd q = triangle_quality(scan.V, scan.F);
  ASSERT_GT((q.array() < 0.1).count(), scan.num_faces() / 100);  // really has slivers
  ASSERT_TRUE(degenerate_faces(scan.V, scan.F).empty());
  const FlowResult result = vertex_flow(scan.V, scan.F);
  expect_guard_had_work(result);  // measured: 275 flipped
  // Measured: 0.165, 0.018, 0.00030, +0.025, 0.041.
  expect_flow_effect(scan, result, {"noisy scan", 0.066, 0.045, 0.00075, 0.01, 0.083});
}

// A flat grid (the saddle's (x, y), z = 0; spacing 2 half / n), its topology and its boundary
// vertices fixed: the guard tests' mesh.
struct FlatGrid {
  Mesh mesh;
  Topology topology;
  std::vector<char> fixed;
};

FlatGrid flat_grid(double half, int n) {
  FlatGrid grid;
  grid.mesh = test::saddle(half, n);
  grid.mesh.V.col(2).setZero();
  grid.topology = build_topology(grid.mesh.F, grid.mesh.num_vertices());
  grid.fixed.assign(static_cast<std::size_t>(grid.mesh.num_vertices()), 0);
  for (std::size_t v = 0; v < grid.fixed.size(); ++v) grid.fixed[v] = grid.topology.is_boundary_vertex[v];
  return grid;
}

// The guard itself (src/guard/guard.h), on a flat grid where the proposed move of one vertex
// flips faces while every other vertex makes a small good move: the guard repairs the flipped
// faces by shortening only the vertex that flipped them, and leaves every other proposed move
// as it was.
TEST(FlowGuard, RepairsBadFacesAndKeepsEveryGoodMove) {
  const FlatGrid grid = flat_grid(5.0, 10);  // 11 x 11 vertices, spacing 1
  const Mesh& flat = grid.mesh;
  const Topology& topology = grid.topology;
  const std::vector<char>& fixed = grid.fixed;
  const Index n = flat.num_vertices();
  // Every free vertex moves by 0.1 along a direction of its own; the centre vertex (5, 5) moves by
  // 1.6 edge lengths, across its neighbours.
  Vertices proposed = flat.V;
  Index centre = -1;
  for (Index v = 0; v < n; ++v) {
    if (fixed[static_cast<std::size_t>(v)]) continue;
    const double angle = 0.7 * static_cast<double>(v);
    proposed.row(v) += 0.1 * Eigen::RowVector3d(std::cos(angle), std::sin(angle), 0);
    if (flat.V.row(v).norm() < 1e-12) centre = v;
  }
  ASSERT_GE(centre, 0);
  proposed.row(centre) = flat.V.row(centre) + Eigen::RowVector3d(1.6, 0.3, 0);
  const std::vector<Index> flipped = flipped_faces(flat.V, proposed, flat.F);
  ASSERT_FALSE(flipped.empty());
  std::vector<char> on_bad_face(static_cast<std::size_t>(n), 0);
  for (const Index f : flipped)
    for (int k = 0; k < 3; ++k) on_bad_face[static_cast<std::size_t>(flat.F(f, k))] = 1;

  GuardOptions options;
  options.min_quality = 0;  // only flips and degenerate faces
  const GuardCriteria criteria = guard_criteria(flat.V, flat.F, options);
  Vertices X = proposed;
  std::vector<char> shortened(static_cast<std::size_t>(n), 0);
  const GuardCounts counts = guard(X, flat.V, criteria, fixed, topology, options, {}, shortened);
  EXPECT_TRUE(flipped_faces(flat.V, X, flat.F).empty());
  EXPECT_EQ(counts.flipped_before_guard, static_cast<Index>(flipped.size()));
  Index kept = 0;
  for (Index v = 0; v < n; ++v) {
    const auto i = static_cast<std::size_t>(v);
    if (!shortened[i]) {
      ASSERT_EQ(X.row(v), proposed.row(v)) << "vertex " << v << " was not shortened but moved";
      ++kept;
    } else {
      // Shortened along its own move: anchor + step * proposed displacement, step in [0, 1).
      const Eigen::RowVector3d d = proposed.row(v) - flat.V.row(v), got = X.row(v) - flat.V.row(v);
      EXPECT_LT(got.norm(), d.norm()) << v;
      EXPECT_LE((got - got.dot(d) / d.squaredNorm() * d).norm(), 1e-12) << v;
    }
  }
  // Only the centre, whose move alone flipped the faces, was shortened: halving any other
  // corner of a flipped face helps that face less (guard.h), and every other free vertex, its
  // neighbours on the flipped faces included, kept its move.
  EXPECT_TRUE(shortened[static_cast<std::size_t>(centre)]);
  EXPECT_EQ(std::count(shortened.begin(), shortened.end(), 1), 1);
  EXPECT_EQ(kept, n - 1);
  EXPECT_GT(std::count(on_bad_face.begin(), on_bad_face.end(), 1), 1);
}

// The guard with thousands of bad faces, where it judges them and picks their corners on all
// threads (guard.cpp, kSerialBelow): the same positions and the same shortened vertices with one
// thread as with two, and no flipped face left. A flat 101 x 101 grid whose free vertices each
// move 0.6 edge lengths in a direction of their own flips thousands of faces (measured: 2,631 of
// 20,000 flipped before the guard, 8,894 vertices shortened).
TEST(FlowGuard, ThousandsOfBadFacesGiveTheSameResultOnAnyThreadCount) {
  const FlatGrid grid = flat_grid(50.0, 100);  // spacing 1
  const Mesh& flat = grid.mesh;
  const Topology& topology = grid.topology;
  const std::vector<char>& fixed = grid.fixed;
  const Index n = flat.num_vertices();
  Vertices proposed = flat.V;
  for (Index v = 0; v < n; ++v) {
    if (fixed[static_cast<std::size_t>(v)]) continue;
    const double angle = 2.3 * static_cast<double>(v);
    proposed.row(v) += 0.6 * Eigen::RowVector3d(std::cos(angle), std::sin(angle), 0);
  }
  const auto flipped_before = static_cast<Index>(flipped_faces(flat.V, proposed, flat.F).size());
  ASSERT_GT(flipped_before, 2048);  // above the guard's serial threshold
  GuardOptions options;
  const GuardCriteria criteria = guard_criteria(flat.V, flat.F, options);
  auto run = [&](int threads, std::vector<char>& shortened) {
    const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threads));
    Vertices X = proposed;
    shortened.assign(static_cast<std::size_t>(n), 0);
    const GuardCounts counts = guard(X, flat.V, criteria, fixed, topology, options, {}, shortened);
    EXPECT_EQ(counts.flipped_before_guard, flipped_before);
    return X;
  };
  std::vector<char> shortened_one, shortened_two;
  const Vertices one = run(1, shortened_one), two = run(2, shortened_two);
  std::cout << "[measured] " << flipped_before << " flipped faces before the guard, "
            << std::count(shortened_two.begin(), shortened_two.end(), 1) << " vertices shortened\n";
  EXPECT_EQ(one, two);
  EXPECT_EQ(shortened_one, shortened_two);
  EXPECT_TRUE(flipped_faces(flat.V, two, flat.F).empty());
  EXPECT_GT(std::count(shortened_two.begin(), shortened_two.end(), 1), 0);
}

// --- The projection's promises (surface_projection.h), measured directly. -------------------

// The crease polylines of a mesh: for each crease vertex, the sharp edges of the chain of
// crease vertices it lies on, up to the corners that end it (or the whole loop).
std::vector<std::vector<Index>> crease_chain_of_vertex(const SurfaceFeatures& features, const Topology& topology) {
  const std::size_t n = features.vertex_kind.size();
  std::vector<int> chain_id(n, -1);
  std::vector<std::vector<Index>> chains;
  for (std::size_t start = 0; start < n; ++start) {
    if (features.vertex_kind[start] != SurfaceFeatures::Kind::Crease || chain_id[start] >= 0) continue;
    const int id = static_cast<int>(chains.size());
    chains.emplace_back();
    std::vector<Index> stack = {static_cast<Index>(start)};
    chain_id[start] = id;
    std::vector<char> edge_taken(features.sharp_edge.size(), 0);
    while (!stack.empty()) {
      const Index v = stack.back();
      stack.pop_back();
      features.for_each_sharp_edge(v, [&](Index e) {
        if (edge_taken[static_cast<std::size_t>(e)]) return;
        edge_taken[static_cast<std::size_t>(e)] = 1;
        chains.back().push_back(e);
        const Index w = topology.edges(e, 0) == v ? topology.edges(e, 1) : topology.edges(e, 0);
        const auto j = static_cast<std::size_t>(w);
        if (features.vertex_kind[j] == SurfaceFeatures::Kind::Crease && chain_id[j] < 0) {
          chain_id[j] = id;
          stack.push_back(w);
        }
      });
    }
  }
  std::vector<std::vector<Index>> per_vertex(n);
  for (std::size_t v = 0; v < n; ++v)
    if (chain_id[v] >= 0) per_vertex[v] = chains[static_cast<std::size_t>(chain_id[v])];
  return per_vertex;
}

double distance_to_segment(const Eigen::Vector3d& x, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const double t = std::clamp((x - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
  return (a + t * (b - a) - x).norm();
}

struct FeatureMotion {
  Index crease_vertices = 0, crease_vertices_moved = 0, corners = 0;
  double worst_crease_distance = 0;  ///< from a crease vertex to its own crease, in edge lengths
  double worst_patch_distance = 0;   ///< from a smooth vertex to its own patch's faces, in edge lengths
};

// Checks the feature promises of the flow's projection on (mesh, result) at `feature_angle`:
// corners do not move, crease vertices end on their own input crease polyline, smooth vertices
// end on (the Phong lift of) their own patch. Returns what it measured.
FeatureMotion expect_features_kept(const Mesh& mesh, const Vertices& result, double feature_angle = 40.0) {
  const Topology topology = build_topology(mesh.F, mesh.num_vertices());
  const SurfaceFeatures features = detect_features(mesh.V, mesh.F, topology, feature_angle);
  const double edge = mean_edge_length(mesh.V, topology);
  const auto chains = crease_chain_of_vertex(features, topology);
  FeatureMotion m;
  std::vector<std::vector<Index>> patch_faces;
  for (Index f = 0; f < mesh.num_faces(); ++f) {
    const auto p = static_cast<std::size_t>(features.face_patch[static_cast<std::size_t>(f)]);
    if (patch_faces.size() <= p) patch_faces.resize(p + 1);
    patch_faces[p].push_back(f);
  }
  std::vector<std::vector<Index>> patch_vertices(patch_faces.size());
  for (Index v = 0; v < mesh.num_vertices(); ++v) {
    const auto i = static_cast<std::size_t>(v);
    switch (features.vertex_kind[i]) {
      case SurfaceFeatures::Kind::Corner:
        ++m.corners;
        EXPECT_EQ(result.row(v), mesh.V.row(v)) << "corner " << v << " moved";
        break;
      case SurfaceFeatures::Kind::Crease: {
        ++m.crease_vertices;
        double d = std::numeric_limits<double>::infinity();
        for (const Index e : chains[i])
          d = std::min(d, distance_to_segment(result.row(v).transpose(), mesh.V.row(topology.edges(e, 0)).transpose(),
                                              mesh.V.row(topology.edges(e, 1)).transpose()));
        m.worst_crease_distance = std::max(m.worst_crease_distance, d / edge);
        m.crease_vertices_moved += (result.row(v) - mesh.V.row(v)).norm() > 0.01 * edge ? 1 : 0;
        break;
      }
      case SurfaceFeatures::Kind::Smooth: {
        if (topology.valence(v) == 0) break;
        const Index f = topology.vertex_faces[static_cast<std::size_t>(topology.face_offsets[i])];
        patch_vertices[static_cast<std::size_t>(features.face_patch[static_cast<std::size_t>(f)])].push_back(v);
        break;
      }
    }
  }
  for (std::size_t p = 0; p < patch_faces.size(); ++p) {
    if (patch_vertices[p].empty()) continue;
    Faces F(static_cast<Index>(patch_faces[p].size()), 3);
    for (std::size_t k = 0; k < patch_faces[p].size(); ++k)
      F.row(static_cast<Index>(k)) = mesh.F.row(patch_faces[p][k]);
    Vertices X(static_cast<Index>(patch_vertices[p].size()), 3);
    for (std::size_t k = 0; k < patch_vertices[p].size(); ++k)
      X.row(static_cast<Index>(k)) = result.row(patch_vertices[p][k]);
    const Eigen::VectorXd d = DistanceQuery(mesh.V, F).squared_distances(X).cwiseSqrt();
    m.worst_patch_distance = std::max(m.worst_patch_distance, d.maxCoeff() / edge);
  }
  EXPECT_LE(m.worst_crease_distance, 1e-9) << "a crease vertex left its crease";
  return m;
}

// An elliptic cylinder with flat caps (a boss of a CAD part): two rims of 90-degree creases that
// are closed loops without corners, along which the curvature varies (semi-axes 1.6 and 0.7), so
// the flow slides rim vertices along the rims; rings along z graded towards the top.
Mesh capped_elliptic_cylinder() {
  const int around = 40, along = 8;
  std::vector<Eigen::Vector3d> points;
  auto ellipse = [&](int i, double scale, double z) {
    const double t = 2 * M_PI * i / around;
    return Eigen::Vector3d(1.6 * scale * std::cos(t), 0.7 * scale * std::sin(t), z);
  };
  for (int j = 0; j <= along; ++j)
    for (int i = 0; i < around; ++i) points.push_back(ellipse(i, 1.0, 2.0 * std::pow(j / double(along), 0.7)));
  const int inner_bottom = static_cast<int>(points.size());
  for (int i = 0; i < around; ++i) points.push_back(ellipse(i, 0.6, 0.0));
  const int inner_top = static_cast<int>(points.size());
  for (int i = 0; i < around; ++i) points.push_back(ellipse(i, 0.6, 2.0));
  const int centre_bottom = static_cast<int>(points.size());
  points.emplace_back(0, 0, 0);
  points.emplace_back(0, 0, 2);
  const int centre_top = centre_bottom + 1;
  std::vector<Eigen::Vector3i> faces;
  auto ring = [&](int base, int i) { return base + (i % around); };
  for (int j = 0; j < along; ++j)
    for (int i = 0; i < around; ++i) {
      const int a = ring(j * around, i), b = ring(j * around, i + 1), c = ring((j + 1) * around, i + 1),
                d = ring((j + 1) * around, i);
      faces.emplace_back(a, b, c);
      faces.emplace_back(a, c, d);
    }
  const int top_rim = along * around;
  for (int i = 0; i < around; ++i) {
    // Bottom cap, facing -z: rim, inner ring, centre.
    faces.emplace_back(ring(0, i), ring(inner_bottom, i), ring(0, i + 1));
    faces.emplace_back(ring(0, i + 1), ring(inner_bottom, i), ring(inner_bottom, i + 1));
    faces.emplace_back(ring(inner_bottom, i), centre_bottom, ring(inner_bottom, i + 1));
    // Top cap, facing +z.
    faces.emplace_back(ring(top_rim, i), ring(top_rim, i + 1), ring(inner_top, i));
    faces.emplace_back(ring(top_rim, i + 1), ring(inner_top, i + 1), ring(inner_top, i));
    faces.emplace_back(ring(inner_top, i), ring(inner_top, i + 1), centre_top);
  }
  Mesh mesh;
  mesh.V.resize(static_cast<Index>(points.size()), 3);
  for (std::size_t k = 0; k < points.size(); ++k) mesh.V.row(static_cast<Index>(k)) = points[k].transpose();
  mesh.F.resize(static_cast<Index>(faces.size()), 3);
  for (std::size_t k = 0; k < faces.size(); ++k) mesh.F.row(static_cast<Index>(k)) = faces[k].transpose();
  return mesh;
}

TEST(FlowProjection, CreaseVerticesStayOnTheirCreasesAndCornersStay) {
  struct Case {
    std::string name;
    Mesh mesh;
    Index min_crease_moved;  // crease vertices that moved by > 0.01 edge lengths: the test has teeth
  };
  std::vector<Case> cases;
  cases.push_back({"fandisk", read_mesh(test::data_path("fandisk.off")), 1});
  cases.push_back({"chamfer-cube", read_mesh(test::data_path("chamfer-cube.off")), 0});
  cases.push_back({"capped elliptic cylinder", capped_elliptic_cylinder(), 1});
  // The flow alone, and followed by density passes (FlowOptions::density), which project as
  // the solve does.
  for (const int passes : {0, 10}) {
    FlowOptions options;
    options.density.passes = passes;
    for (const Case& c : cases) {
      SCOPED_TRACE(c.name + ", " + std::to_string(passes) + " density passes");
      const Topology topology = build_topology(c.mesh.F, c.mesh.num_vertices());
      ASSERT_TRUE(topology.is_manifold() && topology.is_closed());
      const FlowResult result = vertex_flow(c.mesh.V, c.mesh.F, options);
      expect_promises_kept(c.mesh, result);
      const FeatureMotion m = expect_features_kept(c.mesh, result.V);
      std::cout << "[measured] " << c.name << ", " << passes << " density passes: " << m.crease_vertices
                << " crease vertices, " << m.crease_vertices_moved << " moved, " << m.corners
                << " corners, worst crease distance " << m.worst_crease_distance << ", worst patch distance "
                << m.worst_patch_distance << "\n";
      EXPECT_GE(m.crease_vertices_moved, c.min_crease_moved);
      // Measured 0.054 (fandisk), 0.014 (cylinder) for the flow, 0.063 and 0.021 with passes: the
      // Phong lift.
      EXPECT_LE(m.worst_patch_distance, 0.15);
    }
  }
}

// A thin slab (two faces 0.3 edge lengths apart) with the creases of its rims disabled
// (feature_angle 180), so that only the walk keeps a point on its own side: a query point of a
// top vertex pushed below the slab's mid-plane is nearer the bottom face, and a global
// closest-point projection would put it there.
TEST(FlowProjection, NoPointJumpsThroughAThinWall) {
  const Mesh slab = test::perforated_plate(2, 2, 0.3, true);  // 5 x 5 cells, edges 0.5, 0.3 thick
  const Topology topology = build_topology(slab.F, slab.num_vertices());
  const SurfaceFeatures smooth = detect_features(slab.V, slab.F, topology, 180.0);
  const double top = slab.V.col(2).maxCoeff(), bottom = slab.V.col(2).minCoeff();
  std::vector<Index> rows;
  Vertices queries = slab.V;
  for (Index v = 0; v < slab.num_vertices(); ++v) {
    // Top vertices away from the walls (all their faces on top): a wall vertex's query point
    // would lie on the wall itself, which is its own surface.
    bool inside = slab.V(v, 2) == top;
    for (Index k = topology.face_offsets[static_cast<std::size_t>(v)];
         inside && k < topology.face_offsets[static_cast<std::size_t>(v) + 1]; ++k) {
      const Index f = topology.vertex_faces[static_cast<std::size_t>(k)];
      for (int c = 0; c < 3; ++c) inside = inside && slab.V(slab.F(f, c), 2) == top;
    }
    if (!inside) continue;
    rows.push_back(v);
    queries(v, 2) = bottom + 0.3 * (top - bottom);  // nearer the bottom face
  }
  ASSERT_GT(rows.size(), 10u);
  project_near_vertices(queries, rows, slab.V, slab.F, topology, smooth);
  for (const Index v : rows) EXPECT_GT(queries(v, 2), 0.5 * (top + bottom)) << "vertex " << v << " jumped";
}

// The walk's point-triangle query (its own, not CGAL's: surface_projection.cpp says why) against
// DistanceQuery's closest points (CGAL's point-triangle projection over our face tree,
// distance.h) on a flat, irregular grid, where the Phong lift is
// zero: query points above and below the interior land in faces, points beyond the border on
// its edges and at its corners, so every region of the query is exercised.
TEST(FlowProjection, ClosestPointsAgreeWithCgalOnAFlatGrid) {
  Mesh grid = test::height_field(1.0, 12, [](double, double) { return 0.0; });
  const Topology topology = build_topology(grid.F, grid.num_vertices());
  // Jitter the interior vertices in the plane, so faces are not all alike.
  std::mt19937 random(3);
  std::uniform_real_distribution<double> jitter(-0.03, 0.03), offset(-0.12, 0.12), height(-0.2, 0.2);
  for (Index v = 0; v < grid.num_vertices(); ++v)
    if (!topology.is_boundary_vertex[static_cast<std::size_t>(v)]) {
      grid.V(v, 0) += jitter(random);
      grid.V(v, 1) += jitter(random);
    }
  const SurfaceFeatures smooth = detect_features(grid.V, grid.F, topology, 180.0);
  Vertices queries = grid.V;
  std::vector<Index> rows;
  Index beyond = 0;
  for (Index v = 0; v < grid.num_vertices(); ++v) {
    rows.push_back(v);
    queries(v, 0) += offset(random);
    queries(v, 1) += offset(random);
    queries(v, 2) = height(random);
    beyond += std::abs(queries(v, 0)) > 1.0 || std::abs(queries(v, 1)) > 1.0;
  }
  const std::vector<ClosestPoint> expected = DistanceQuery(grid.V, grid.F).closest_points(queries);
  project_near_vertices(queries, rows, grid.V, grid.F, topology, smooth);
  double worst = 0;
  for (Index v = 0; v < grid.num_vertices(); ++v)
    worst = std::max(worst, (queries.row(v).transpose() - expected[static_cast<std::size_t>(v)].point).norm());
  std::cout << "[measured] flat grid: " << rows.size() << " queries, " << beyond
            << " beyond the border; largest difference from CGAL " << worst << "\n";
  EXPECT_GT(beyond, 10);
  EXPECT_LT(worst, 1e-12);
}

TEST(FlowProjection, VerticesStayOnTheInputSurfaceAndCreasesStayCrisp) {
  // fandisk: a CAD part with sharp creases. Without the projection vertices leave the surface;
  // with it every vertex lies on the input (Phong-lifted, so within a small fraction of an
  // edge of the facets) and no vertex leaves a crease: the sharp-edge polylines keep their
  // vertices on the input's sharp edges.
  const Mesh mesh = read_mesh(test::data_path("fandisk.off"));
  const FlowResult projected = vertex_flow(mesh.V, mesh.F);
  FlowOptions free_options;
  free_options.project_to_input = false;
  const FlowResult free = vertex_flow(mesh.V, mesh.F, free_options);
  const double edge = projected.report.mean_edge_length;
  // Exact distances through DistanceQuery (distance.h; checked against brute force there).
  const DistanceQuery input_surface(mesh.V, mesh.F);
  auto distance_to_input = [&](const Vertices& X) -> Eigen::VectorXd {
    return input_surface.squared_distances(X).cwiseSqrt();
  };
  const Eigen::VectorXd on = distance_to_input(projected.V) / edge, off = distance_to_input(free.V) / edge;
  std::cout << "[measured] fandisk distance to the input in edge lengths: projected mean " << on.mean() << " max "
            << on.maxCoeff() << ", unprojected mean " << off.mean() << "\n";
  // Measured: projected mean 0.0022 and max 0.054 (the Phong lift of the curved parts),
  // unprojected mean 0.018 (8.3x).
  EXPECT_LT(on.mean(), 0.0055);
  EXPECT_LT(on.maxCoeff(), 0.14);
  EXPECT_GT(off.mean(), 3 * on.mean());
  // Corners do not move, crease vertices stay on their creases (measured directly).
  expect_features_kept(mesh, projected.V);
}

TEST(FlowProjection, FairnessTargetKeepsTheIcosahedronStill) {
  // All twelve vertices are alike: with the paper's fairness target (zero) every vertex is
  // pulled inwards and the solid shrinks; with the default target the input is at rest.
  const Mesh ico = test::icosphere(1.0, 0);
  FlowOptions paper;
  paper.weights.fairness_target = FairnessTarget::Zero;
  paper.project_to_input = false;
  FlowOptions ours = paper;
  ours.weights.fairness_target = FairnessTarget::InputNormal;
  const double volume = signed_volume(ico.V, ico.F);
  EXPECT_LT(signed_volume(vertex_flow(ico.V, ico.F, paper).V, ico.F), 0.98 * volume);  // measured -5% (flow.h)
  EXPECT_NEAR(signed_volume(vertex_flow(ico.V, ico.F, ours).V, ico.F), volume, 1e-9 * volume);
}

TEST(Flow, SimilarityTransformCommutes) {
  // The method commutes exactly; the solve only to its tolerance (at the default 1e-4 the two
  // differed by 1.4e-4 of the diagonal), so it runs to 1e-6 here to see the method's part.
  FlowOptions options;
  options.solver_tolerance = 1e-6;
  const Mesh mesh = read_mesh(test::data_path("spot.obj"));
  const FlowResult base = vertex_flow(mesh.V, mesh.F, options);
  expect_moved(mesh, base.V, 0.1);  // measured 0.262
  const double s = 3.7;
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.9, Eigen::Vector3d(1, -2, 0.5).normalized()).toRotationMatrix();
  const Eigen::RowVector3d t(5, -1, 12);
  auto transform = [&](const Vertices& X) -> Vertices { return (s * (X * R.transpose())).rowwise() + t; };
  const FlowResult moved = vertex_flow(transform(mesh.V), mesh.F, options);
  const double scale = s * bounding_box(mesh.V).diagonal();
  EXPECT_LE((moved.V - transform(base.V)).cwiseAbs().maxCoeff(), 1e-6 * scale);
}

TEST(Flow, PinnedVerticesStay) {
  const Mesh mesh = read_mesh(test::data_path("bunny_uniform.off"));
  FlowOptions options;
  const FlowResult free_result = vertex_flow(mesh.V, mesh.F, options);
  // Pin the vertices that moved most.
  Eigen::VectorXd moved = (free_result.V - mesh.V).rowwise().norm();
  for (int k = 0; k < 5; ++k) {
    Index worst = 0;
    moved.maxCoeff(&worst);
    options.constraints.pinned.push_back(worst);
    moved[worst] = -1;
  }
  const FlowResult pinned = vertex_flow(mesh.V, mesh.F, options);
  for (const Index v : options.constraints.pinned) EXPECT_EQ(pinned.V.row(v), mesh.V.row(v)) << v;
  expect_moved(mesh, pinned.V, 0.056);  // the rest still flows (measured 0.14 unpinned)
  EXPECT_EQ(pinned.report.fixed_vertices, free_result.report.fixed_vertices + 5);
  FlowOptions out_of_range;
  out_of_range.constraints.pinned = {mesh.num_vertices()};
  EXPECT_THROW(vertex_flow(mesh.V, mesh.F, out_of_range), std::invalid_argument);
}

TEST(Flow, LargerLambdaMovesLess) {
  const Mesh mesh = read_mesh(test::data_path("bunny_uniform.off"));
  double previous = std::numeric_limits<double>::infinity();
  for (const double lambda : {0.2, 1.0, 10.0, 50.0}) {
    FlowOptions options;
    options.weights.lambda = lambda;
    const double moved = mean_displacement(vertex_flow(mesh.V, mesh.F, options).V, mesh.V);
    EXPECT_LT(moved, previous) << "lambda " << lambda;
    previous = moved;
  }
}

TEST(Flow, RepeatedSolvesStartFromGuardedMeshes) {
  // Regression: with the guard only after the last solve, fandisk's third unguarded solve left
  // 671 flipped or degenerate faces, the curvature on them reached 1e15 per mean edge length and
  // the fourth solve failed ("the normal matrix is not positive definite").
  const Mesh mesh = read_mesh(test::data_path("fandisk.off"));
  FlowOptions options;
  options.iterations = 5;
  FlowResult result;
  ASSERT_NO_THROW(result = vertex_flow(mesh.V, mesh.F, options));
  // Five solves move vertices further than one; the promises hold after each.
  expect_promises_kept(mesh, result, options);
  EXPECT_GT(mean_displacement(result.V, mesh.V), mean_displacement(vertex_flow(mesh.V, mesh.F).V, mesh.V));
}

TEST(Flow, RefusesEmptyMeshesAndNonManifoldOnesWhenAsked) {
  const Mesh bowtie = test::bowtie();
  FlowOptions strict;
  strict.refuse_non_manifold = true;
  EXPECT_THROW(vertex_flow(bowtie.V, bowtie.F, strict), std::invalid_argument);
  // By default the bowtie flows with its shared vertex held (and the rest on the boundary).
  const FlowResult held = vertex_flow(bowtie.V, bowtie.F);
  EXPECT_EQ(held.V, bowtie.V);
  EXPECT_EQ(held.report.held_non_manifold_vertices, 1);
  EXPECT_THROW(vertex_flow(Vertices(), Faces()), std::invalid_argument);
}

// The overload that takes the topology frees what only the set-up reads and changes nothing
// else: the same bytes as the one that borrows it, on fandisk (its creases are what the freed
// fields serve in the set-up) and on a non-manifold mesh (fandisk and a torus sharing a vertex:
// the flow runs on the split, with a topology of its own).
TEST(Flow, TakingTheTopologyGivesTheSameBytesAndFreesTheSetUpsParts) {
  const Mesh fandisk = read_mesh(test::data_path("fandisk.off"));
  Mesh joined = fandisk;
  const Mesh torus = test::torus(0.3, 0.1, 24, 12);
  const Index offset = fandisk.num_vertices();
  joined.V.conservativeResize(offset + torus.num_vertices(), 3);
  joined.V.bottomRows(torus.num_vertices()) = torus.V.rowwise() + fandisk.V.row(0);
  joined.F.conservativeResize(fandisk.num_faces() + torus.num_faces(), 3);
  for (Index f = 0; f < torus.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) {
      const Index v = torus.F(f, k);
      joined.F(fandisk.num_faces() + f, k) = v == 0 ? 0 : offset + v;  // torus vertex 0 is fandisk's
    }
  for (const Mesh* mesh : std::initializer_list<const Mesh*>{&fandisk, &joined}) {
    const Topology borrowed = build_topology(mesh->F, mesh->num_vertices());
    const FlowResult lent = vertex_flow(mesh->V, mesh->F, borrowed);
    Topology taken = build_topology(mesh->F, mesh->num_vertices());
    const bool manifold = taken.is_manifold();
    const FlowResult given = vertex_flow(mesh->V, mesh->F, std::move(taken));
    expect_moved(*mesh, given.V, 0.1);
    EXPECT_TRUE((lent.V.array() == given.V.array()).all());
    EXPECT_EQ(borrowed.face_edges.rows(), mesh->num_faces());  // the borrowed one stays whole
    if (manifold) {                                            // the flow ran on this topology, not on a split's
      EXPECT_EQ(taken.face_adjacency.rows(), 0);           // NOLINT(bugprone-use-after-move): flow.h leaves it trimmed
      EXPECT_TRUE(taken.edge_face_count.empty());          // NOLINT(bugprone-use-after-move)
      EXPECT_EQ(taken.num_edges(), borrowed.num_edges());  // NOLINT(bugprone-use-after-move)
    }
  }
}

TEST(Flow, DeterministicBetweenRuns) {
  const Mesh mesh = read_mesh(test::data_path("max-planck-5k.obj"));
  const Vertices first = vertex_flow(mesh.V, mesh.F).V;
  expect_moved(mesh, first, 0.1);  // measured 0.262
  EXPECT_EQ(vertex_flow(mesh.V, mesh.F).V, first);
}

// FlowOptions::fix_boundary = false: boundary vertices move, over the input surface.
TEST(Flow, FreeBoundaryMovesTheBoundaryOverTheInput) {
  const Mesh mesh = read_mesh(test::data_path("hemisphere.off"));
  FlowOptions options;
  options.constraints.fix_boundary = false;
  const FlowResult result = vertex_flow(mesh.V, mesh.F, options);
  expect_promises_kept(mesh, result, options);
  const Topology topology = build_topology(mesh.F, mesh.num_vertices());
  const DistanceQuery input(mesh.V, mesh.F);
  Index moved = 0, boundary = 0;
  double worst = 0;
  for (Index v = 0; v < mesh.num_vertices(); ++v) {
    if (!topology.is_boundary_vertex[static_cast<std::size_t>(v)]) continue;
    ++boundary;
    moved += (result.V.row(v) - mesh.V.row(v)).norm() > 0.01 * result.report.mean_edge_length ? 1 : 0;
    worst = std::max(worst, std::sqrt(input.squared_distances(result.V.row(v)).maxCoeff()));
  }
  std::cout << "[measured] free boundary: " << moved << " of " << boundary
            << " boundary vertices moved, worst distance " << worst / result.report.mean_edge_length << "\n";
  EXPECT_GT(moved, boundary / 2);                            // measured: all 120
  EXPECT_LE(worst, 0.016 * result.report.mean_edge_length);  // measured 0.0063
  EXPECT_LT(result.report.fixed_vertices, vertex_flow(mesh.V, mesh.F).report.fixed_vertices);
}

// FlowOptions::feature_angle: at 180 nothing is a corner or a crease, so fandisk's corners
// (held at the default 40 degrees) move.
TEST(Flow, FeatureAngleDecidesWhichVerticesAreHeld) {
  const Mesh mesh = read_mesh(test::data_path("fandisk.off"));
  const Topology topology = build_topology(mesh.F, mesh.num_vertices());
  const SurfaceFeatures features = detect_features(mesh.V, mesh.F, topology, 40.0);
  FlowOptions options;
  options.feature_angle = 180;
  const FlowResult result = vertex_flow(mesh.V, mesh.F, options);
  expect_promises_kept(mesh, result, options);
  Index corners = 0, corners_moved = 0;
  for (Index v = 0; v < mesh.num_vertices(); ++v) {
    if (features.vertex_kind[static_cast<std::size_t>(v)] != SurfaceFeatures::Kind::Corner) continue;
    ++corners;
    corners_moved += (result.V.row(v) - mesh.V.row(v)).norm() > 0.01 * result.report.mean_edge_length ? 1 : 0;
  }
  std::cout << "[measured] feature angle 180: " << corners_moved << " of " << corners << " corners moved\n";
  EXPECT_GT(corners_moved, corners / 2);  // measured: all 22
  EXPECT_LT(result.report.fixed_vertices, vertex_flow(mesh.V, mesh.F).report.fixed_vertices);
}

// FlowOptions::max_halvings = 1: a vertex of a bad face goes straight back to where it started
// (one solve: the input), where the default halves its move instead.
TEST(Flow, OneHalvingSendsEveryLimitedVertexHome) {
  const Mesh scan = test::noisy_scan(read_mesh(test::data_path("bunny_uniform.off")), 0.15, 0.6, 7);
  // At the input up to the rounding of the normalised frame (flow.h: the flow runs on a
  // translated, scaled copy; only fixed vertices are copied back bit for bit).
  const double rounding = 1e-12 * bounding_box(scan.V).diagonal();
  auto at_input = [&](const Vertices& X) {
    Index count = 0;
    for (Index v = 0; v < scan.num_vertices(); ++v) count += (X.row(v) - scan.V.row(v)).norm() <= rounding ? 1 : 0;
    return count;
  };
  FlowOptions options;
  options.guard.max_halvings = 1;
  const FlowResult once = vertex_flow(scan.V, scan.F, options), halved = vertex_flow(scan.V, scan.F);
  expect_promises_kept(scan, once, options);
  std::cout << "[measured] max_halvings 1: " << once.report.limited_vertices << " limited, " << at_input(once.V)
            << " at the input; default: " << halved.report.limited_vertices << " limited, " << at_input(halved.V)
            << " at the input\n";
  ASSERT_GT(once.report.limited_vertices, 0);
  // Every limited and every fixed vertex is at the input (and a few free vertices the solve did
  // not move: 25 of the 5,314 measured).
  EXPECT_GE(at_input(once.V), once.report.limited_vertices + once.report.fixed_vertices);
  EXPECT_LT(at_input(halved.V), halved.report.limited_vertices + halved.report.fixed_vertices);
}

TEST(Flow, RejectsInvalidOptionsAndRepeatedVertexFaces) {
  const Mesh mesh = read_mesh(test::data_path("spot.obj"));
  FlowOptions options;
  options.d_percentile = -1;
  EXPECT_THROW(vertex_flow(mesh.V, mesh.F, options), std::invalid_argument);
  options.d_percentile = std::nan("");
  EXPECT_THROW(vertex_flow(mesh.V, mesh.F, options), std::invalid_argument);
  Faces bad = mesh.F;
  bad(0, 1) = bad(0, 0);
  EXPECT_THROW(vertex_flow(mesh.V, bad), std::invalid_argument);
}

// Every option out of its range is refused by the library itself (not only by the CLI), with
// a message that names the option; the defaults are valid.
TEST(Flow, ValidatesEveryOptionAndNamesIt) {
  const Mesh mesh = test::icosphere(1.0, 0);
  EXPECT_NO_THROW(validate_flow_options(FlowOptions{}, mesh.num_vertices()));
  const double nan = std::nan("");
  const std::vector<std::pair<std::string, std::function<void(FlowOptions&)>>> cases = {
      {"lambda", [](FlowOptions& o) { o.weights.lambda = 0; }},
      {"lambda", [](FlowOptions& o) { o.weights.lambda = -1; }},
      {"lambda", [&](FlowOptions& o) { o.weights.lambda = nan; }},
      {"mu", [](FlowOptions& o) { o.weights.mu = -0.5; }},
      {"mu", [](FlowOptions& o) { o.weights.mu = std::numeric_limits<double>::infinity(); }},
      {"epsilon", [](FlowOptions& o) { o.weights.epsilon = 0; }},
      {"sliver", [](FlowOptions& o) { o.weights.sliver = -0.1; }},
      {"sliver", [&](FlowOptions& o) { o.weights.sliver = nan; }},
      {"d_percentile", [](FlowOptions& o) { o.d_percentile = 101; }},
      {"iterations", [](FlowOptions& o) { o.iterations = 0; }},
      {"feature_angle", [&](FlowOptions& o) { o.feature_angle = nan; }},
      {"max_halvings", [](FlowOptions& o) { o.guard.max_halvings = 0; }},
      {"min_quality", [](FlowOptions& o) { o.guard.min_quality = 1.5; }},
      {"solver_tolerance", [](FlowOptions& o) { o.solver_tolerance = 0; }},
      {"smoothing_rounds", [](FlowOptions& o) { o.curvature.smoothing_rounds = -1; }},
      {"pinned vertex 12",
       [](FlowOptions& o) {
         o.constraints.pinned = {0, 12};
       }},
      {"pinned vertex -1", [](FlowOptions& o) { o.constraints.pinned = {-1}; }},
  };
  for (const auto& [name, set] : cases) {
    FlowOptions options;
    set(options);
    try {
      vertex_flow(mesh.V, mesh.F, options);
      ADD_FAILURE() << name << ": accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
    }
  }
}

// The overload that takes the caller's topology gives the same bytes, and refuses a topology
// of another mesh.
TEST(Flow, TakesTheCallersTopology) {
  const Mesh mesh = read_mesh(test::data_path("spot.obj"));
  const Topology topology = build_topology(mesh.F, mesh.num_vertices());
  const Vertices own = vertex_flow(mesh.V, mesh.F).V;
  expect_moved(mesh, own, 0.1);  // measured 0.262
  EXPECT_EQ(vertex_flow(mesh.V, mesh.F, topology).V, own);
  const Mesh other = test::icosphere(1.0, 0);
  EXPECT_THROW(vertex_flow(mesh.V, mesh.F, build_topology(other.F, other.num_vertices())), std::invalid_argument);
}

TEST(Flow, FacesDegenerateInTheInputDoNotStallTheGuard) {
  // Append a zero-area face (three collinear new vertices): it cannot be judged and is left
  // as it is, while the rest of the mesh flows.
  Mesh mesh = read_mesh(test::data_path("spot.obj"));
  const Index n = mesh.num_vertices();
  mesh.V.conservativeResize(n + 3, 3);
  mesh.V.row(n) << 5, 5, 5;
  mesh.V.row(n + 1) << 6, 5, 5;
  mesh.V.row(n + 2) << 7, 5, 5;
  mesh.F.conservativeResize(mesh.F.rows() + 1, 3);
  mesh.F.row(mesh.F.rows() - 1) << n, n + 1, n + 2;
  const FlowResult result = vertex_flow(mesh.V, mesh.F);
  EXPECT_TRUE(flipped_faces(mesh.V, result.V, mesh.F).empty());
  EXPECT_GT(mean_displacement(result.V.topRows(n), mesh.V.topRows(n)), 0.0);
}

TEST(Flow, AMeshWithoutExtentIsRefusedInsteadOfLoopedOn) {
  // Issue 12: a closed tetrahedron with its four vertices at one point (or at coordinates whose
  // squares underflow) made the guard loop forever. Each call runs under a watchdog.
  const Faces F = (Faces(4, 3) << 0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3).finished();
  for (const double scale : {0.0, 1e-170}) {
    SCOPED_TRACE(scale);
    Vertices V(4, 3);
    V << 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1;
    if (scale > 0) V = (Vertices(4, 3) << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1).finished() * scale;
    auto outcome = std::async(std::launch::async, [&] {
      try {
        vertex_flow(V, F);
        return std::string("accepted");
      } catch (const std::invalid_argument& e) {
        return std::string(e.what());
      }
    });
    if (outcome.wait_for(std::chrono::seconds(60)) == std::future_status::timeout) {
      ADD_FAILURE() << "vertex_flow still running after 60 s (it takes milliseconds when it refuses)";
      std::_Exit(1);  // the hung thread cannot be joined
    }
    EXPECT_NE(outcome.get().find("the bounding box has zero size"), std::string::npos);
  }
}

// Issue 32 item 1: the unit square as a 20 x 20 grid in z = 0, two triangles per cell (split by
// the diagonal from (i, j) to (i + 1, j + 1)), without the cells of [7, 12)^2 when `hole`, with
// uniform z-noise of +-`noise` (fixed seed).
Mesh flat_grid(bool hole, double noise) {
  constexpr int n = 20;
  Mesh grid;
  grid.V.resize(n * n, 3);
  std::mt19937 random(32);
  std::uniform_real_distribution<double> jitter(-noise, noise);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) grid.V.row(j * n + i) << i / (n - 1.0), j / (n - 1.0), noise > 0 ? jitter(random) : 0;
  std::vector<Index> corners;
  for (int j = 0; j + 1 < n; ++j)
    for (int i = 0; i + 1 < n; ++i) {
      if (hole && i >= 7 && i < 12 && j >= 7 && j < 12) continue;
      const Index a = j * n + i, b = a + 1, c = a + n, d = c + 1;
      corners.insert(corners.end(), {a, b, d, a, d, c});
    }
  grid.F = Eigen::Map<const Faces>(corners.data(), static_cast<Eigen::Index>(corners.size() / 3), 3);
  return grid;
}

// A surface without features comes back unchanged (flow.h, kFlatCurvature). Before, the
// fairness rows of the fixed rim slid the flat grid's 324 inner vertices by up to 1.95 mean edge
// lengths (the grid with a hole: 288 by up to 1.07; with 1e-12 of noise, whose curvature d
// normalised, by up to 0.44; the flow on the grid as its own reference as far as on the input).
TEST(Flow, ASurfaceWithoutFeaturesComesBackUnchanged) {
  for (const auto& [hole, noise] : {std::pair{false, 0.0}, std::pair{true, 0.0}, std::pair{false, 1e-12}}) {
    SCOPED_TRACE(::testing::Message() << "hole " << hole << ", noise " << noise);
    const Mesh grid = flat_grid(hole, noise);
    const double edge = mean_edge_length(grid.V, build_topology(grid.F, grid.num_vertices()));
    for (const bool on_reference : {false, true}) {
      SCOPED_TRACE(on_reference ? "on itself as the reference" : "on the input");
      const FlowResult result =
          on_reference ? vertex_flow_on_reference(grid.V, grid.F, grid.V, grid.F) : vertex_flow(grid.V, grid.F);
      EXPECT_TRUE(result.report.flat);
      // Measured: 0 on the input (bit for bit), 0 on the reference (its own closest points).
      EXPECT_LE((result.V - grid.V).rowwise().norm().maxCoeff() / edge, 1e-6);
    }
  }
}

// The bound is far from real shapes: a shallow dome 1% of its width high (largest |k| times the
// diagonal 0.113, 113 times kFlatCurvature) still flows (measured: mean move 0.034 edge lengths).
TEST(Flow, AShallowDomeIsNotFlat) {
  Mesh dome = flat_grid(false, 0.0);
  for (Index v = 0; v < dome.num_vertices(); ++v)
    dome.V(v, 2) = 0.01 * (1 - 4 * (std::pow(dome.V(v, 0) - 0.5, 2) + std::pow(dome.V(v, 1) - 0.5, 2)));
  const FlowResult result = vertex_flow(dome.V, dome.F);
  EXPECT_FALSE(result.report.flat);
  expect_moved(dome, result.V, 0.01);
}

}  // namespace
}  // namespace vertexflow

namespace vertexflow {
namespace {

// Issue 15: non-manifold input (flow.h, manifold_split.h). Vertex-clustered versions of the dense
// bunny, as the Stanford low-resolution scans were made (about 5.2k, 3.0k and 1.4k vertices,
// 93-182 non-manifold vertices each): the flow runs, keeps its promises, holds the non-manifold
// vertices bit for bit and redistributes the rest. Measured: rho +0.179, +0.195, +0.153 (input
// 0.016, 0.006, 0.008); the guard does not limit it (with min_quality 0 it is +0.180, +0.196,
// +0.155), the energy does: at lambda 0.3 and 2 iterations +0.240, +0.224, +0.191. The
// issue's +0.2 is reached by the density passes (DensityOnClusteredBunny,
// docs/redistribution.md says why the paper's energy stops short).
class FlowOnClusteredBunny : public ::testing::TestWithParam<double> {};

TEST_P(FlowOnClusteredBunny, HoldsNonManifoldVerticesAndFlowsTheRest) {
  const Mesh mesh = test::clustered_bunny(GetParam());
  const Topology topology = build_topology(mesh.F, mesh.num_vertices());
  ASSERT_FALSE(topology.is_manifold());
  const FlowResult result = vertex_flow(mesh.V, mesh.F);
  expect_promises_kept(mesh, result);
  EXPECT_GT(result.report.held_non_manifold_vertices, 0);
  for (const Index v : topology.non_manifold_vertices) ASSERT_EQ(result.V.row(v), mesh.V.row(v)) << v;
  expect_moved(mesh, result.V, 0.08);
  const test::RhoChange rho = test::redistribution_rho_change(mesh, result.V);
  std::cout << "[measured] clustered bunny " << GetParam() << ": " << mesh.num_vertices() << " vertices, "
            << result.report.held_non_manifold_vertices << " held, rho " << rho.before << " -> " << rho.after << "\n";
  EXPECT_GE(rho.gain(), 0.06);
}

INSTANTIATE_TEST_SUITE_P(CellSizes, FlowOnClusteredBunny, ::testing::Values(0.015, 0.02, 0.03),
                         [](const auto& param_info) { return "cell_" + std::to_string(int(1000 * param_info.param)); });

// Faces reversed against their neighbours are turned back for the computation: the flow gives
// the same bytes as on the consistently oriented mesh.
TEST(FlowNonManifold, ReversedFacesFlowAsTheOrientedMesh) {
  const Mesh mesh = read_mesh(test::data_path("spot.obj"));
  Mesh flipped = mesh;
  for (Index f = 0; f < mesh.num_faces(); f += 97) std::swap(flipped.F(f, 1), flipped.F(f, 2));
  ASSERT_FALSE(build_topology(flipped.F, flipped.num_vertices()).is_oriented);
  const FlowResult result = vertex_flow(flipped.V, flipped.F);
  EXPECT_EQ(result.V, vertex_flow(mesh.V, mesh.F).V);
  EXPECT_EQ(result.report.reoriented_faces, (mesh.num_faces() + 96) / 97);
  EXPECT_EQ(result.report.held_non_manifold_vertices, 0);
  FlowOptions strict;
  strict.refuse_non_manifold = true;
  EXPECT_THROW(vertex_flow(flipped.V, flipped.F, strict), std::invalid_argument);
}

}  // namespace
}  // namespace vertexflow
