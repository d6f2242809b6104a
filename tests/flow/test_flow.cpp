// vertex_flow end to end on real meshes: the guarantees (no flips, no degenerate faces, fixed
// and pinned vertices stay), invariance under similarity transforms, the lambda knob, volume.
#include "shapes.h"
#include "test_support.h"

#include "vertexflow/compare.h"
#include "vertexflow/distance.h"
#include "vertexflow/flow.h"
#include "vertexflow/io.h"
#include "vertexflow/quality.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <functional>
#include <future>
#include <iostream>
#include <limits>

namespace vertexflow {
namespace {

double mean_displacement(const Vertices& a, const Vertices& b) {
  return (a - b).rowwise().norm().mean();
}

// The guarantees of issue 4 on any mesh: no flipped or degenerate faces, boundary fixed,
// volume kept (closed meshes of data/; not required of the hard cases), triangle quality 2r/R >= 0.25 wherever the
// input's is >= 0.5, and fewer than 0.1% of faces below 0.3 (or no more than the input had, where it already had more).
void expect_flow_guarantees(const Mesh& mesh, const FlowResult& result, bool check_volume = true) {
  EXPECT_TRUE(flipped_faces(mesh.V, result.V, mesh.F).empty());
  EXPECT_TRUE(degenerate_faces(result.V, mesh.F).empty());
  EXPECT_TRUE(result.V.allFinite());
  // The flow moved something, but not far: displacement in mean edge lengths.
  const double moved = mean_displacement(result.V, mesh.V) / result.report.mean_edge_length;
  EXPECT_LT(moved, 1.0);
  const Topology topology = build_topology(mesh.F, mesh.num_vertices());
  for (Index v = 0; v < mesh.num_vertices(); ++v) {
    if (topology.is_boundary_vertex[static_cast<std::size_t>(v)]) {
      ASSERT_EQ(result.V.row(v), mesh.V.row(v)) << v;
    }
  }
  // Drift (issue 4): mean distance from the result's surface to the input's <= 0.05 mean edge
  // lengths (area samples, exact distances: distance.h).
  SamplingOptions sampling;
  sampling.samples = 50000;
  const double drift = one_sided_distance(result.V, mesh.F, mesh.V, mesh.F, sampling).mean;
  EXPECT_LE(drift, 0.05 * result.report.mean_edge_length);
  if (check_volume && topology.is_closed()) {
    const double before = signed_volume(mesh.V, mesh.F), after = signed_volume(result.V, mesh.F);
    EXPECT_LT(std::abs(after - before), 0.005 * std::abs(before));
  }
  const Eigen::VectorXd q_in = triangle_quality(mesh.V, mesh.F), q_out = triangle_quality(result.V, mesh.F);
  Index below_in = 0, below_out = 0;
  for (Index f = 0; f < mesh.num_faces(); ++f) {
    if (q_in[f] >= 0.5) {
      ASSERT_GE(q_out[f], 0.25) << "face " << f;
    }
    below_in += q_in[f] < 0.3 ? 1 : 0;
    below_out += q_out[f] < 0.3 ? 1 : 0;
  }
  EXPECT_LE(below_out, std::max<Index>(below_in, static_cast<Index>(0.001 * static_cast<double>(mesh.num_faces()))));
}

class FlowOnMesh : public ::testing::TestWithParam<const char*> {};

TEST_P(FlowOnMesh, KeepsTheGuarantees) {
  const Mesh mesh = read_mesh(test::data_path(GetParam()));
  expect_flow_guarantees(mesh, vertex_flow(mesh.V, mesh.F));
}

INSTANTIATE_TEST_SUITE_P(Data, FlowOnMesh,
                         ::testing::Values("bunny_uniform.off", "fandisk.off", "max-planck-5k.obj", "hemisphere.off",
                                           "camelhead.off", "spot.obj", "torus.obj", "fertility.off", "rocker-arm.obj",
                                           "bunny_adaptive.off", "amo_adaptive.off", "sphere_low.off", "suzanne.obj",
                                           "fandisk_quads.off", "chamfer-cube.off", "icosahedron_binary.stl"),
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

// Hard cases (issue 4): an unguarded solve flips faces on each; the guarded flow must not.
TEST(FlowHardCases, ThinPerforatedPlateOfGenus16) {
  const Mesh plate = test::perforated_plate(4, 4, 0.1, true);
  const Topology topology = build_topology(plate.F, plate.num_vertices());
  ASSERT_TRUE(topology.is_manifold());
  ASSERT_EQ(topology.genus(), 16);
  const FlowResult result = vertex_flow(plate.V, plate.F);
  expect_flow_guarantees(plate, result, false);
  std::cout << "perforated plate: " << result.report.flipped_before_guard << " faces flipped before the guard\n";
}

TEST(FlowHardCases, OpenPlateWithHolesKeepsItsBoundaryLoops) {
  const Mesh plate = test::perforated_plate(3, 4, 0.25, false);
  const Topology topology = build_topology(plate.F, plate.num_vertices());
  ASSERT_TRUE(topology.is_manifold());
  ASSERT_EQ(topology.boundary_loops.size(), 10u);  // 9 holes and the outer rim
  expect_flow_guarantees(plate, vertex_flow(plate.V, plate.F));
}

TEST(FlowHardCases, NoisyScanWithSlivers) {
  const Mesh scan = test::noisy_scan(read_mesh(test::data_path("bunny_uniform.off")), 0.15, 0.6, 7);
  const Eigen::VectorXd q = triangle_quality(scan.V, scan.F);
  ASSERT_GT((q.array() < 0.1).count(), scan.num_faces() / 100);  // really has slivers
  ASSERT_TRUE(degenerate_faces(scan.V, scan.F).empty());
  const FlowResult result = vertex_flow(scan.V, scan.F);
  expect_flow_guarantees(scan, result, false);
  std::cout << "noisy scan: " << result.report.flipped_before_guard << " faces flipped before the guard\n";
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
  // Exact distances through the AABB tree (distance.h; checked against brute force there).
  const DistanceQuery input_surface(mesh.V, mesh.F);
  auto distance_to_input = [&](const Vertices& X) -> Eigen::VectorXd {
    return input_surface.squared_distances(X).cwiseSqrt();
  };
  const Eigen::VectorXd on = distance_to_input(projected.V) / edge, off = distance_to_input(free.V) / edge;
  EXPECT_LT(on.mean(), 0.01);
  EXPECT_LT(on.maxCoeff(), 0.1);
  EXPECT_GT(off.mean(), 2 * on.mean());
  // Corners (fixed) do not move; the result keeps the input's sharp edges sharp: the number of
  // edges whose dihedral angle exceeds 40 degrees does not drop.
  auto sharp_edges = [&](const Vertices& X) {
    const Topology t = build_topology(mesh.F, mesh.num_vertices());
    Index count = 0;
    for (Index f = 0; f < mesh.num_faces(); ++f) {
      for (int k = 0; k < 3; ++k) {
        const Index g = t.face_adjacency(f, k);
        if (g <= f) continue;
        const Eigen::Vector3d a = face_normal(X, mesh.F, f).normalized(), b = face_normal(X, mesh.F, g).normalized();
        count += a.dot(b) < std::cos(40.0 * M_PI / 180.0) ? 1 : 0;
      }
    }
    return count;
  };
  EXPECT_GE(sharp_edges(projected.V), 0.98 * static_cast<double>(sharp_edges(mesh.V)));
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
  EXPECT_LT(signed_volume(vertex_flow(ico.V, ico.F, paper).V, ico.F), 0.99 * volume);
  EXPECT_NEAR(signed_volume(vertex_flow(ico.V, ico.F, ours).V, ico.F), volume, 1e-9 * volume);
}

TEST(Flow, SimilarityTransformCommutes) {
  const Mesh mesh = read_mesh(test::data_path("spot.obj"));
  const FlowResult base = vertex_flow(mesh.V, mesh.F);
  const double s = 3.7;
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.9, Eigen::Vector3d(1, -2, 0.5).normalized()).toRotationMatrix();
  const Eigen::RowVector3d t(5, -1, 12);
  auto transform = [&](const Vertices& X) -> Vertices { return (s * (X * R.transpose())).rowwise() + t; };
  const FlowResult moved = vertex_flow(transform(mesh.V), mesh.F);
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
    options.pinned.push_back(worst);
    moved[worst] = -1;
  }
  const FlowResult pinned = vertex_flow(mesh.V, mesh.F, options);
  for (const Index v : options.pinned) EXPECT_EQ(pinned.V.row(v), mesh.V.row(v)) << v;
  EXPECT_EQ(pinned.report.fixed_vertices, free_result.report.fixed_vertices + 5);
  FlowOptions out_of_range;
  out_of_range.pinned = {mesh.num_vertices()};
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
  // The guard's guarantees (five solves move vertices further than expect_flow_guarantees'
  // one-solve bound of a mean edge length, so that check does not apply).
  EXPECT_TRUE(result.V.allFinite());
  EXPECT_TRUE(flipped_faces(mesh.V, result.V, mesh.F).empty());
  EXPECT_TRUE(degenerate_faces(result.V, mesh.F).empty());
  const Eigen::VectorXd q_in = triangle_quality(mesh.V, mesh.F), q_out = triangle_quality(result.V, mesh.F);
  for (Index f = 0; f < mesh.num_faces(); ++f) ASSERT_GE(q_out[f], std::min(0.3, q_in[f]) - 1e-12) << "face " << f;
}

TEST(Flow, RefusesNonManifoldAndEmptyMeshes) {
  const Mesh bowtie = test::bowtie();
  EXPECT_THROW(vertex_flow(bowtie.V, bowtie.F), std::invalid_argument);
  EXPECT_THROW(vertex_flow(Vertices(), Faces()), std::invalid_argument);
}

TEST(Flow, DeterministicBetweenRuns) {
  const Mesh mesh = read_mesh(test::data_path("max-planck-5k.obj"));
  EXPECT_EQ(vertex_flow(mesh.V, mesh.F).V, vertex_flow(mesh.V, mesh.F).V);
}

TEST(Flow, GuardCountsOnlyVerticesItShortened) {
  // max-planck-5k has slivers the unguarded solve flips; pin every third vertex.
  const Mesh mesh = read_mesh(test::data_path("max-planck-5k.obj"));
  FlowOptions options;
  for (Index v = 0; v < mesh.num_vertices(); v += 3) options.pinned.push_back(v);
  const FlowResult result = vertex_flow(mesh.V, mesh.F, options);
  EXPECT_TRUE(flipped_faces(mesh.V, result.V, mesh.F).empty());
  Index moved_less = 0;
  for (Index v = 0; v < mesh.num_vertices(); ++v) moved_less += v % 3 != 0 ? 1 : 0;
  EXPECT_LE(result.report.limited_vertices, moved_less);
  for (Index v = 0; v < mesh.num_vertices(); v += 3) ASSERT_EQ(result.V.row(v), mesh.V.row(v));
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
      {"d_percentile", [](FlowOptions& o) { o.d_percentile = 101; }},
      {"iterations", [](FlowOptions& o) { o.iterations = 0; }},
      {"feature_angle", [&](FlowOptions& o) { o.feature_angle = nan; }},
      {"max_halvings", [](FlowOptions& o) { o.max_halvings = 0; }},
      {"min_quality", [](FlowOptions& o) { o.min_quality = 1.5; }},
      {"solver_tolerance", [](FlowOptions& o) { o.solver_tolerance = 0; }},
      {"smoothing_rounds", [](FlowOptions& o) { o.curvature.smoothing_rounds = -1; }},
      {"pinned vertex 12",
       [](FlowOptions& o) {
         o.pinned = {0, 12};
       }},
      {"pinned vertex -1", [](FlowOptions& o) { o.pinned = {-1}; }},
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
  EXPECT_EQ(vertex_flow(mesh.V, mesh.F, topology).V, vertex_flow(mesh.V, mesh.F).V);
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

}  // namespace
}  // namespace vertexflow
