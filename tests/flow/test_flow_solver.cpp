// The flow's linear solvers (src/flow/flow_solver.h): the direct factorisation against an
// independent reference (H probed through the operator, Eigen's LDLT), the
// iterative paths (block-Jacobi and multilevel) against the direct one on real meshes (same
// minimiser, same energy), the multilevel preconditioner's effect, the automatic choice and its
// fallback, and identical bytes for any thread count.
#include "shapes.h"
#include "test_support.h"

#include "flow_operator.h"
#include "flow_setup.h"
#include "flow_solver.h"
#include "flow_terms.h"
#include "numerics/aggregation_coarse_space.h"
#include "numerics/conjugate_gradients.h"
#include "vertexflow/io.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>
#include <Eigen/Geometry>
#include <Eigen/SparseCholesky>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <new>
#include <numeric>
#include <tuple>

namespace vertexflow {
namespace {

// The problem vertex_flow solves in its first round, without its projection and guard, set up
// by the flow's own preparation (flow_setup.h): normalised to mean edge length 1, boundary and
// corner vertices fixed.
struct Problem {
  Mesh mesh;
  Topology topology;
  FlowFrame frame;
  std::vector<char> fixed;
};

Problem make_problem(Mesh mesh) {
  Problem p;
  p.mesh = std::move(mesh);
  p.topology = build_topology(p.mesh.F, p.mesh.num_vertices());
  const FlowOptions options;
  FlowSetup setup = prepare_flow(p.mesh.V, p.mesh.F, p.topology, options);
  p.frame = flow_frame(setup.input, p.mesh.F, p.topology, options, setup.sliver_faces);
  p.fixed = std::move(setup.fixed);
  return p;
}

Vertices solve(const Problem& p, LinearSolver kind, const EnergyWeights& weights = {}, FlowReport* report = nullptr,
               double tolerance = 1e-9) {
  FlowReport local;
  FlowSystemSolver solver(p.topology, p.fixed, kind, tolerance);
  Vertices Y = solver.solve(p.frame, weights, report ? *report : local);
  return Y;
}

// The minimiser by a path independent of both solvers' machinery: H's columns over the free
// coordinates probed with unit vectors through the operator (whose agreement with the paper's
// formulas test_flow_energy.cpp checks), then H d = b by Eigen's sparse LDLT. The direct
// solver assembles H from star sums instead (normal_matrix.h), the iterative ones never form it.
Vertices reference_solution(const Problem& p, const EnergyWeights& weights) {
  const Index n = p.mesh.num_vertices();
  std::vector<Index> order(static_cast<std::size_t>(n));
  std::iota(order.begin(), order.end(), 0);
  const FlowTerms terms = make_flow_terms(p.topology, p.fixed, p.frame, weights, order);
  FlowOperator op(terms);
  const BlockVector b = op.right_hand_side(to_local(terms, p.frame.P.data()));
  std::vector<Eigen::Index> column(3 * static_cast<std::size_t>(n), -1);
  std::vector<Eigen::Index> coordinate;  // free column -> coordinate
  for (Index i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k)
      if (!p.fixed[static_cast<std::size_t>(i)]) {
        column[3 * static_cast<std::size_t>(i) + k] = static_cast<Eigen::Index>(coordinate.size());
        coordinate.push_back(3 * i + k);
      }
  const auto m = static_cast<Eigen::Index>(coordinate.size());
  std::vector<Eigen::Triplet<double>> triplets;
  BlockVector unit = BlockVector::Zero(3 * n), h(3 * n);
  for (Eigen::Index c = 0; c < m; ++c) {
    unit[coordinate[static_cast<std::size_t>(c)]] = 1;
    op.apply(unit, h);
    unit[coordinate[static_cast<std::size_t>(c)]] = 0;
    for (Eigen::Index r = 0; r < h.size(); ++r) {
      const Eigen::Index row = column[static_cast<std::size_t>(r)];
      if (h[r] != 0 && row >= 0) triplets.emplace_back(row, c, h[r]);
    }
  }
  Eigen::SparseMatrix<double> H(m, m);
  H.setFromTriplets(triplets.begin(), triplets.end());
  Eigen::VectorXd rhs(m);
  for (Eigen::Index c = 0; c < m; ++c) rhs[c] = b[coordinate[static_cast<std::size_t>(c)]];
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(H);
  EXPECT_EQ(ldlt.info(), Eigen::Success);
  const Eigen::VectorXd x = ldlt.solve(rhs);
  Vertices Y = p.frame.P;
  for (Eigen::Index c = 0; c < m; ++c) Y.data()[coordinate[static_cast<std::size_t>(c)]] += x[c];
  return Y;
}

double max_difference(const Vertices& a, const Vertices& b) {
  return (a - b).cwiseAbs().maxCoeff();
}

TEST(FlowSolver, AllPathsMatchTheProbedReference) {
  // hemisphere: a boundary (fixed vertices); both fairness targets.
  const Problem p = make_problem(read_mesh(test::data_path("hemisphere.off")));
  for (const FairnessTarget target : {FairnessTarget::InputNormal, FairnessTarget::Zero}) {
    EnergyWeights weights;
    weights.fairness_target = target;
    const Vertices reference = reference_solution(p, weights);
    ASSERT_GT(max_difference(reference, p.frame.P), 0.01);  // the solve moves vertices
    // Units: mean edge lengths. The direct path is exact up to rounding.
    EXPECT_LT(max_difference(solve(p, LinearSolver::Direct, weights), reference), 1e-9);
    EXPECT_LT(max_difference(solve(p, LinearSolver::Iterative, weights), reference), 1e-6);
    EXPECT_LT(max_difference(solve(p, LinearSolver::Multilevel, weights), reference), 1e-6);
  }
}

// Direct and iterative give the same minimiser and the same energy on real meshes, including a
// CAD part whose flat faces make the iteration slow (fandisk), a scan with a boundary
// (camelhead) and a small lambda (stronger flow, weaker distance term).
struct AgreeCase {
  const char* file;
  double lambda;
};

class FlowSolverAgree : public ::testing::TestWithParam<AgreeCase> {};

TEST_P(FlowSolverAgree, SameMinimiserAndEnergy) {
  const Problem p = make_problem(read_mesh(test::data_path(GetParam().file)));
  EnergyWeights weights;
  weights.lambda = GetParam().lambda;
  FlowReport direct_report;
  const Vertices direct = solve(p, LinearSolver::Direct, weights, &direct_report);
  EXPECT_EQ(direct_report.solver_used, LinearSolver::Direct);
  EXPECT_LT(direct_report.solver_error, 1e-12);
  const double e_direct = total_flow_energy(direct, p.topology, p.frame, weights);
  EXPECT_LT(e_direct, total_flow_energy(p.frame.P, p.topology, p.frame, weights));
  for (const LinearSolver kind : {LinearSolver::Iterative, LinearSolver::Multilevel}) {
    FlowReport report;
    const Vertices iterative = solve(p, kind, weights, &report);
    EXPECT_EQ(report.solver_used, kind);
    EXPECT_LE(report.solver_error, 1e-9);
    EXPECT_GT(report.solver_iterations, 0);
    // Measured differences: 3e-9 (bunny) to 3e-7 (fandisk) mean edge lengths.
    EXPECT_LT(max_difference(direct, iterative), 2e-6);
    // The energy gap equals |d_it - d_direct|^2 in H's norm: relative 1e-12 or less measured.
    EXPECT_NEAR(total_flow_energy(iterative, p.topology, p.frame, weights), e_direct, 1e-10 * e_direct);
  }
}

TEST(FlowSolver, MultilevelRemovesTheSlowModesOfFlatRegions) {
  // fandisk's flat faces leave tangential motion to F_smo's bi-Laplacian: block-Jacobi needs
  // about a thousand iterations, the multilevel preconditioner a few times fewer (measured at
  // this tolerance: 1,124 against 162). On a smooth mesh both are fast, and the coarse space
  // still helps (bunny_uniform: 102 against 72).
  for (const auto& [file, ratio] : {std::pair{"fandisk.off", 4.0}, std::pair{"bunny_uniform.off", 1.2}}) {
    const Problem p = make_problem(read_mesh(test::data_path(file)));
    FlowReport block_jacobi, multilevel;
    solve(p, LinearSolver::Iterative, {}, &block_jacobi);
    solve(p, LinearSolver::Multilevel, {}, &multilevel);
    EXPECT_GT(block_jacobi.solver_iterations, ratio * multilevel.solver_iterations) << file;
  }
}

// The multilevel iterations to the default tolerance with the hierarchy's prolongators of
// `kind` (the solver's other choices as FlowSystemSolver makes them, in the mesh's own order).
int multilevel_iterations(const Problem& p, const FlowTerms& terms, AdditiveMultilevel::Prolongators kind) {
  FlowOperator op(terms);
  const BlockVector b = op.right_hand_side(to_local(terms, p.frame.P.data()));
  auto space = std::make_shared<const AggregationCoarseSpace>(terms.ring_start, terms.ring, terms.fixed);
  CoarseSpaceCorrection correction(space, galerkin_upper(terms, *space), kind);
  ConjugateGradients cg(op, block_jacobi(terms), b, &correction);
  const IterationResult result = cg.run(2000, FlowOptions{}.solver_tolerance);
  EXPECT_TRUE(result.converged);
  return result.iterations;
}

TEST(FlowSolver, HierarchyIsSmoothedWherePlanarRegionsNeedIt) {
  // The rule of multilevel_prolongators picks the prolongators that take fewer iterations:
  // smoothed on large planar faces, tentative on curved surfaces. Measured (smoothed,
  // tentative): the rounded cube 80, 93; fandisk 58, 64; the icosphere 10, 10; the torus 16,
  // 12; amo 55, 40. Moving, scaling or renumbering the mesh does not change the choice.
  using Kind = AdditiveMultilevel::Prolongators;
  const Mesh fandisk = read_mesh(test::data_path("fandisk.off"));
  Mesh moved = fandisk;  // rotated about a skew axis, scaled by 1000, shifted, faces reversed in order
  const Eigen::Matrix3d rotation = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  moved.V = ((1000.0 * fandisk.V * rotation.transpose()).rowwise() + Eigen::RowVector3d(5, -7, 11)).eval();
  moved.F = fandisk.F.colwise().reverse().eval();
  const std::tuple<const char*, Mesh, Kind> cases[] = {
      {"rounded cube", test::rounded_cube(1.0, 0.3, 48), Kind::Smoothed},
      {"fandisk", fandisk, Kind::Smoothed},
      {"fandisk moved", moved, Kind::Smoothed},
      {"icosphere", test::icosphere(1.0, 5), Kind::Tentative},
      {"torus", test::torus(2.0, 0.7, 160, 64), Kind::Tentative},
      {"amo", read_mesh(test::data_path("amo.off")), Kind::Tentative},
  };
  for (const auto& [name, mesh, expected] : cases) {
    const Problem p = make_problem(mesh);
    std::vector<Index> order(static_cast<std::size_t>(p.mesh.num_vertices()));
    std::iota(order.begin(), order.end(), 0);
    const FlowTerms terms = make_flow_terms(p.topology, p.fixed, p.frame, {}, order);
    const Kind chosen = multilevel_prolongators(terms);
    EXPECT_EQ(chosen, expected) << name;
    const int smoothed = multilevel_iterations(p, terms, Kind::Smoothed);
    const int tentative = multilevel_iterations(p, terms, Kind::Tentative);
    EXPECT_LE(chosen == Kind::Smoothed ? smoothed : tentative, chosen == Kind::Smoothed ? tentative : smoothed)
        << name << ": smoothed " << smoothed << ", tentative " << tentative;
  }
}

INSTANTIATE_TEST_SUITE_P(Data, FlowSolverAgree,
                         ::testing::Values(AgreeCase{"bunny_uniform.off", 1.0}, AgreeCase{"fandisk.off", 1.0},
                                           AgreeCase{"max-planck-5k.obj", 1.0}, AgreeCase{"camelhead.off", 1.0},
                                           AgreeCase{"spot.obj", 0.2}),
                         [](const auto& param_info) {
                           return test::test_name(std::string(param_info.param.file) + "_lambda_" +
                                                  std::to_string(static_cast<int>(10 * param_info.param.lambda)));
                         });

// Two meshes side by side as one (two components).
Mesh disjoint_union(const Mesh& a, const Mesh& b) {
  Mesh m;
  m.V.resize(a.V.rows() + b.V.rows(), 3);
  m.V << a.V, (b.V.rowwise() + Eigen::RowVector3d(10, 0, 0));
  m.F.resize(a.F.rows() + b.F.rows(), 3);
  m.F << a.F, (b.F.array() + static_cast<Index>(a.V.rows())).matrix();
  return m;
}

TEST(FlowSolver, MultilevelAgreesWithTheFactorisationOnHardCases) {
  // Shapes that stress the aggregation: high genus, boundaries (fixed vertices cut through
  // aggregates), slivers, two components, and a mesh so small that the coarse problem is
  // factored at once.
  const Mesh bunny = read_mesh(test::data_path("bunny_uniform.off"));
  const std::pair<const char*, Mesh> cases[] = {
      {"perforated plate, genus 16", test::perforated_plate(4, 4, 0.1, true)},
      {"open plate with 9 holes", test::perforated_plate(3, 4, 0.25, false)},
      {"noisy scan with slivers", test::noisy_scan(bunny, 0.15, 0.6, 7)},
      {"two components", disjoint_union(test::torus(2.0, 0.7, 40, 16), read_mesh(test::data_path("sphere_low.off")))},
      {"sphere_low (589 vertices)", read_mesh(test::data_path("sphere_low.off"))},
  };
  for (const auto& [name, mesh] : cases) {
    const Problem p = make_problem(mesh);
    FlowReport report;
    const Vertices multilevel = solve(p, LinearSolver::Multilevel, {}, &report);
    EXPECT_EQ(report.solver_used, LinearSolver::Multilevel) << name;
    EXPECT_LE(report.solver_error, 1e-9) << name;
    EXPECT_LT(max_difference(multilevel, solve(p, LinearSolver::Direct)), 2e-6) << name;
  }
}

TEST(FlowSolver, AutomaticChoice) {
  // Tiny meshes are factored; larger ones iterate.
  FlowReport small, large;
  solve(make_problem(read_mesh(test::data_path("sphere_low.off"))), LinearSolver::Automatic, {}, &small);
  EXPECT_EQ(small.solver_used, LinearSolver::Direct);
  EXPECT_EQ(small.solver_iterations, 0);
  const Problem bunny = make_problem(read_mesh(test::data_path("bunny_uniform.off")));
  solve(bunny, LinearSolver::Automatic, {}, &large);
  EXPECT_EQ(large.solver_used, LinearSolver::Iterative);
  EXPECT_GT(large.solver_iterations, 0);
  // fandisk's large flat faces (|k1| + |k2| = 0) take the multilevel preconditioner.
  const Problem fandisk = make_problem(read_mesh(test::data_path("fandisk.off")));
  FlowReport flat;
  solve(fandisk, LinearSolver::Automatic, {}, &flat);
  EXPECT_EQ(flat.solver_used, LinearSolver::Multilevel);
  // spot has no large flat region, but its first 30 block-Jacobi iterations predict a long run
  // (at the default tolerance: 222 in all): the iteration continues with the multilevel
  // preconditioner (88 in all).
  const Problem spot = make_problem(read_mesh(test::data_path("spot.obj")));
  FlowReport switched, forced;
  const Vertices switched_result = solve(spot, LinearSolver::Automatic, {}, &switched);
  solve(spot, LinearSolver::Iterative, {}, &forced);
  EXPECT_EQ(switched.solver_used, LinearSolver::Multilevel);
  EXPECT_GT(switched.solver_iterations, 30);
  EXPECT_LT(2 * switched.solver_iterations, forced.solver_iterations);
  EXPECT_LE(switched.solver_error, 1e-9);
  EXPECT_LT(max_difference(switched_result, solve(spot, LinearSolver::Direct)), 2e-6);
  // A weak distance term, a tinier pull and no F_sliver (which stiffens camelhead's slivers)
  // make camelhead's iteration exhaust its budget, 18 sqrt(free vertices): the factorisation
  // takes over and gives the exact minimiser.
  const Problem camelhead = make_problem(read_mesh(test::data_path("camelhead.off")));
  EnergyWeights weak;
  weak.lambda = 0.01;
  weak.epsilon = 1e-9;
  weak.sliver = 0;
  FlowReport fallback;
  const Vertices Y = solve(camelhead, LinearSolver::Automatic, weak, &fallback);
  EXPECT_EQ(fallback.solver_used, LinearSolver::Direct);
  const auto free_vertices = static_cast<double>(std::count(camelhead.fixed.begin(), camelhead.fixed.end(), 0));
  EXPECT_EQ(fallback.solver_iterations, static_cast<int>(std::ceil(18.0 * std::sqrt(free_vertices))));
  EXPECT_LT(fallback.solver_error, 1e-12);
  EXPECT_LT(max_difference(Y, solve(camelhead, LinearSolver::Direct, weak)), 1e-12);
}

TEST(FlowSolver, SameBytesForAnyThreadCount) {
  // max-planck-5k: Automatic starts with block-Jacobi and switches to the multilevel
  // preconditioner after its first iterations.
  const Problem p = make_problem(read_mesh(test::data_path("max-planck-5k.obj")));
  for (const LinearSolver kind :
       {LinearSolver::Iterative, LinearSolver::Direct, LinearSolver::Multilevel, LinearSolver::Automatic}) {
    Vertices one, two;
    {
      tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
      one = solve(p, kind);
    }
    {
      tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
      two = solve(p, kind);
    }
    EXPECT_EQ(one, two);
    EXPECT_EQ(solve(p, kind), two);
  }
}

TEST(FlowSolver, VertexFlowSameBytesForAnyThreadCount) {
  // bunny_uniform takes the iterative path under LinearSolver::Automatic.
  const Mesh mesh = read_mesh(test::data_path("bunny_uniform.off"));
  Vertices one, two;
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
    one = vertex_flow(mesh.V, mesh.F).V;
  }
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
    two = vertex_flow(mesh.V, mesh.F).V;
  }
  EXPECT_EQ(one, two);
  // The flow ran (mean displacement 0.14 mean edge lengths measured).
  EXPECT_GT((one - mesh.V).rowwise().norm().mean(),
            0.056 * mean_edge_length(mesh.V, build_topology(mesh.F, mesh.num_vertices())));
}

TEST(FlowSolver, SetUpDoesNotDependOnWhereItLives) {
  // The centroid was Eigen's V.colwise().mean(), whose rounding followed the address of its
  // destination modulo 16: the flow's bytes changed with FlowSetup's layout. Built at two
  // addresses 8 bytes apart, the set-up must be the same, and the centroid the row-order mean.
  const Mesh mesh = read_mesh(test::data_path("fandisk.off"));
  const Topology topology = build_topology(mesh.F, mesh.num_vertices());
  const FlowOptions options;
  struct alignas(64) Buffer {
    unsigned char bytes[sizeof(FlowSetup) + 16];
  };
  Buffer buffer[2];
  FlowSetup* at[2];
  for (int k = 0; k < 2; ++k)
    at[k] = new (buffer[k].bytes + 8 * k) FlowSetup(prepare_flow(mesh.V, mesh.F, topology, options));
  ASSERT_NE(reinterpret_cast<std::uintptr_t>(at[0]->centroid.data()) % 16,
            reinterpret_cast<std::uintptr_t>(at[1]->centroid.data()) % 16);
  Eigen::RowVector3d sum = Eigen::RowVector3d::Zero();
  for (Eigen::Index i = 0; i < mesh.V.rows(); ++i)
    for (int c = 0; c < 3; ++c) sum[c] += mesh.V(i, c);
  for (int k = 0; k < 2; ++k) {
    for (int c = 0; c < 3; ++c) EXPECT_EQ(at[k]->centroid[c], sum[c] / static_cast<double>(mesh.V.rows()));
    EXPECT_EQ(at[k]->input, at[0]->input);
  }
  for (FlowSetup* setup : at) setup->~FlowSetup();
}

TEST(FlowSolver, ReusesItsAnalysisAcrossSolves) {
  // A second solve on moved positions (options.iterations > 1) reuses the ordering and the
  // symbolic factorisation; it must equal a fresh solver's result.
  Problem p = make_problem(read_mesh(test::data_path("spot.obj")));
  FlowSystemSolver solver(p.topology, p.fixed, LinearSolver::Direct);
  FlowReport report;
  const Vertices first = solver.solve(p.frame, {}, report);
  p.frame.P = first;
  p.frame.curvature = principal_curvatures(first, p.mesh.F, p.topology);
  const Vertices second = solver.solve(p.frame, {}, report);
  EXPECT_LT(max_difference(second, solve(p, LinearSolver::Direct)), 1e-12);
}

TEST(FlowSolver, RejectsBadTolerance) {
  const Problem p = make_problem(test::torus(2.0, 0.7, 20, 8));
  EXPECT_THROW(FlowSystemSolver(p.topology, p.fixed, LinearSolver::Iterative, 0.0), std::invalid_argument);
  EXPECT_THROW(FlowSystemSolver(p.topology, p.fixed, LinearSolver::Iterative, 1.0), std::invalid_argument);
}

TEST(FlowSolver, FlowOptionsSelectTheSolver) {
  const Mesh mesh = read_mesh(test::data_path("bunny_uniform.off"));
  FlowOptions options;
  options.solver = LinearSolver::Direct;
  const FlowResult direct = vertex_flow(mesh.V, mesh.F, options);
  EXPECT_EQ(direct.report.solver_used, LinearSolver::Direct);
  for (const LinearSolver kind : {LinearSolver::Iterative, LinearSolver::Multilevel}) {
    options.solver = kind;
    const FlowResult iterative = vertex_flow(mesh.V, mesh.F, options);
    EXPECT_EQ(iterative.report.solver_used, kind);
    // At the default tolerance (1e-4): measured 3.1e-3 (block-Jacobi) and 1.1e-3 (multilevel)
    // mean edge lengths, within what flow.h gives for solver_tolerance.
    EXPECT_LT(max_difference(direct.V, iterative.V), 1e-2 * direct.report.mean_edge_length);
  }
}

}  // namespace
}  // namespace vertexflow
