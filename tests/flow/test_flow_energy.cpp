// The flow's energy: the operator that the solver runs (src/flow/flow_operator.h, on the factors
// of flow_terms.h) against the direct evaluation of the paper's formulas (flow_energy.h), term
// by term; and the gradient of F_em used in Eq. 13-19 is its true gradient.
#include "shapes.h"
#include "test_support.h"

#include "flow_operator.h"
#include "flow_setup.h"
#include "flow_terms.h"
#include "vertexflow/flow_energy.h"
#include "vertexflow/io.h"

#include <gtest/gtest.h>

#include <numeric>
#include <random>

namespace vertexflow {
namespace {

struct EnergyCase {
  Mesh mesh;
  Topology topology;
  FlowFrame frame;
  Vertices X;  // a perturbed position set to evaluate at
};

EnergyCase make_setup(Mesh mesh, double perturbation, unsigned seed) {
  EnergyCase s;
  s.mesh = std::move(mesh);
  s.topology = build_topology(s.mesh.F, s.mesh.num_vertices());
  s.frame.P = s.mesh.V;
  s.frame.curvature = principal_curvatures(s.mesh.V, s.mesh.F, s.topology);
  s.frame.d = 0.37;
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, perturbation);
  s.X = s.mesh.V;
  for (Eigen::Index i = 0; i < s.X.size(); ++i) s.X.data()[i] += noise(rng);
  return s;
}

// E(X) - E(P) as the solver sees it, every vertex free: the energy is quadratic in d = X - P,
// E(P + d) = E(P) - 2 b . d + d . H d with H and b from the running operator. A shuffled local
// order, so that the renumbering is exercised too.
double energy_change(const EnergyCase& s, const EnergyWeights& weights, const Vertices& X) {
  std::vector<Index> order(static_cast<std::size_t>(s.mesh.num_vertices()));
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), std::mt19937(5));
  const std::vector<char> fixed(order.size(), 0);
  const FlowTerms terms = make_flow_terms(s.topology, fixed, s.frame, weights, order);
  FlowOperator op(terms);
  const BlockVector b = op.right_hand_side(to_local(terms, s.frame.P.data()));
  const Vertices displacement = X - s.frame.P;
  const BlockVector d = to_local(terms, displacement.data());
  BlockVector Hd(d.size());
  const double dHd = op.apply(d, Hd);
  EXPECT_NEAR(dHd, d.dot(Hd), 1e-12 * std::abs(dHd));  // the fused dot product
  return dHd - 2 * b.dot(d);
}

// Relative tolerance of an energy the running operator computes from its float factors
// (flow_terms.h): 3x the 6.1e-8 measured (EachTermMatchesItsFormula, SliverTermMatchesItsFormula).
constexpr double kFloatFactors = 2e-7;

class EnergyEncoding : public ::testing::TestWithParam<int> {
 protected:
  EnergyCase make_case() const {
    switch (GetParam()) {
      case 0:
        return make_setup(test::torus(2.0, 0.7, 40, 16), 0.02, 1);
      case 1:
        return make_setup(read_mesh(test::data_path("fandisk.off")), 0.01, 2);
      default:
        return make_setup(read_mesh(test::data_path("hemisphere.off")), 0.005, 3);
    }
  }
};

TEST_P(EnergyEncoding, EachTermMatchesItsFormula) {
  const EnergyCase s = make_case();
  const double f_tan = tangential_edge_energy(s.X, s.topology, s.frame);
  const double f_sd = squared_distance_energy(s.X, s.frame);
  const double f_smo = fairness_energy(s.X, s.topology, s.frame);
  const double pull = (s.X - s.frame.P).squaredNorm() / static_cast<double>(s.X.rows());
  ASSERT_GT(f_tan, 0);
  ASSERT_GT(f_sd, 0);
  ASSERT_GT(f_smo, 0);

  // At P itself F_sd and the pull are 0; F_tan and F_smo are not (P is not their minimiser).
  const Vertices& P = s.frame.P;
  const double f_tan_p = tangential_edge_energy(P, s.topology, s.frame);
  const double f_smo_p = fairness_energy(P, s.topology, s.frame);
  ASSERT_EQ(squared_distance_energy(P, s.frame), 0);

  // Switch the terms on one at a time; each change of the running operator's quadratic equals
  // that of its formula. Rounding: the operator's per-vertex factors K, G, P, D are stored in
  // float (flow_terms.h), so its quadratic is that of factors rounded to 6e-8: measured 6.1e-8
  // of the sum on the torus, fandisk and the hemisphere; a term encoded wrongly is off by O(1).
  const double only_tan = energy_change(s, {0.0, 0.0, 0.0}, s.X);
  EXPECT_NEAR(only_tan, f_tan - f_tan_p, kFloatFactors * (f_tan + f_tan_p));
  const double with_sd = energy_change(s, {2.5, 0.0, 0.0}, s.X);
  EXPECT_NEAR(with_sd - only_tan, 2.5 * f_sd, kFloatFactors * (f_tan + f_tan_p + f_sd));
  const double with_smo = energy_change(s, {0.0, 0.7, 0.0}, s.X);
  EXPECT_NEAR(with_smo - only_tan, 0.7 * (f_smo - f_smo_p), kFloatFactors * (f_tan + f_tan_p + f_smo + f_smo_p));
  const EnergyWeights defaults;
  const double total = energy_change(s, defaults, s.X);
  const double total_p = total_flow_energy(P, s.topology, s.frame, defaults);
  const double total_x = total_flow_energy(s.X, s.topology, s.frame, defaults);
  EXPECT_NEAR(total, total_x - total_p, kFloatFactors * (total_x + total_p));
  EXPECT_NEAR(total_x, f_tan + defaults.lambda * f_sd + defaults.mu * f_smo + defaults.epsilon * defaults.lambda * pull,
              1e-12 * total_x);
}

TEST_P(EnergyEncoding, EdgeGradientIsTheGradientOfTheEdgeEnergy) {
  const EnergyCase s = make_case();
  const Vertices g = edge_metric_gradient(s.X, s.topology, s.frame);
  const double edges = s.topology.num_edges();
  std::mt19937 rng(11);
  std::uniform_int_distribution<Index> pick(0, s.mesh.num_vertices() - 1);
  for (int trial = 0; trial < 20; ++trial) {
    const Index i = pick(rng);
    for (int k = 0; k < 3; ++k) {
      // F_em is quadratic, so the central difference is exact up to rounding.
      const double h = 1e-4;
      Vertices plus = s.X, minus = s.X;
      plus(i, k) += h;
      minus(i, k) -= h;
      const double numeric =
          (edge_metric_energy(plus, s.topology, s.frame) - edge_metric_energy(minus, s.topology, s.frame)) / (2 * h);
      EXPECT_NEAR(g(i, k) / edges, numeric, 1e-7 * (std::abs(numeric) + g.row(i).norm() / edges)) << i << " " << k;
    }
  }
}

TEST_P(EnergyEncoding, FairnessTargetsMatchTheirFormulas) {
  // Direct evaluation of Eq. 8-10: mu_i = exp(-(|k1| + |k2|)), L the uniform umbrella, with the
  // paper's target (zero) and the default one (the normal part of the input's umbrella).
  const EnergyCase s = make_case();
  const Curvature& c = s.frame.curvature;
  double paper = 0, ours = 0;
  for (Index i = 0; i < s.mesh.num_vertices(); ++i) {
    const auto [begin, end] = s.topology.ring(i);
    Eigen::Vector3d mean_x = Eigen::Vector3d::Zero(), mean_p = Eigen::Vector3d::Zero();
    for (const Index* j = begin; j != end; ++j) {
      mean_x += s.X.row(*j).transpose();
      mean_p += s.frame.P.row(*j).transpose();
    }
    const double degree = static_cast<double>(end - begin);
    const Eigen::Vector3d L = s.X.row(i).transpose() - mean_x / degree;
    const Eigen::Vector3d Lp = s.frame.P.row(i).transpose() - mean_p / degree;
    const Eigen::Vector3d n = c.N.row(i).transpose();
    const double mu_i = std::exp(-(std::abs(c.k1[i]) + std::abs(c.k2[i])));
    paper += mu_i * L.squaredNorm();
    ours += mu_i * (L - Lp.dot(n) * n).squaredNorm();
  }
  const double nv = static_cast<double>(s.mesh.num_vertices());
  EXPECT_NEAR(fairness_energy(s.X, s.topology, s.frame, FairnessTarget::Zero), paper / nv, 1e-12 * paper / nv);
  EXPECT_NEAR(fairness_energy(s.X, s.topology, s.frame, FairnessTarget::InputNormal), ours / nv, 1e-12 * paper / nv);
  // And the running operator reproduces each.
  const double only_tan = energy_change(s, {0.0, 0.0, 0.0}, s.X);
  for (const FairnessTarget target : {FairnessTarget::Zero, FairnessTarget::InputNormal}) {
    const double change = energy_change(s, {0.0, 1.0, 0.0, target}, s.X) - only_tan;
    const double formula =
        fairness_energy(s.X, s.topology, s.frame, target) - fairness_energy(s.frame.P, s.topology, s.frame, target);
    EXPECT_NEAR(change, formula, 1e-10 * (paper / nv + std::abs(formula)));
  }
}

INSTANTIATE_TEST_SUITE_P(Meshes, EnergyEncoding, ::testing::Values(0, 1, 2));

// F_sliver's encoding: with random positive semi-definite blocks S_i in the frame, the running
// operator's change equals sliver * F_sliver's formula.
TEST_P(EnergyEncoding, SliverTermMatchesItsFormula) {
  EnergyCase s = make_case();
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> entry(-1.0, 1.0);
  s.frame.sliver_stiffness.resize(static_cast<std::size_t>(s.mesh.num_vertices()));
  for (Eigen::Matrix3d& block : s.frame.sliver_stiffness) {
    Eigen::Matrix3d a;
    for (Eigen::Index k = 0; k < 9; ++k) a.data()[k] = entry(rng);
    block = a * a.transpose();
  }
  const double f_sliver = sliver_energy(s.X, s.frame);
  ASSERT_GT(f_sliver, 0);
  EXPECT_EQ(sliver_energy(s.frame.P, s.frame), 0);
  EnergyWeights only_tan{0.0, 0.0, 0.0};
  only_tan.sliver = 0;
  EnergyWeights with_sliver = only_tan;
  with_sliver.sliver = 3.0;
  const double tan = energy_change(s, only_tan, s.X);
  EXPECT_NEAR(energy_change(s, with_sliver, s.X) - tan, 3.0 * f_sliver, kFloatFactors * (std::abs(tan) + f_sliver));
}

// F_sliver's blocks (flow_setup.h): a corner that moves towards its opposite edge by its
// altitude costs 1, along that edge 0; the corners of faces that are not slivers cost nothing.
TEST(SliverStiffness, CornerMovingByItsAltitudeCostsOne) {
  Mesh mesh;
  mesh.V.resize(4, 3);
  mesh.V << 0, 0, 0, 1, 0, 0, 0.5, 0.05, 0, 0.5, -0.8, 0;
  mesh.F.resize(2, 3);
  mesh.F << 0, 1, 2, 1, 0, 3;
  const Topology topology = build_topology(mesh.F, mesh.num_vertices());
  const FlowFrame frame = flow_frame(mesh.V, mesh.F, topology, FlowOptions{}, {0});
  ASSERT_EQ(frame.sliver_stiffness.size(), 4u);
  const Eigen::Matrix3d& apex = frame.sliver_stiffness[2];
  const Eigen::Vector3d towards_edge(0, -0.05, 0), along_edge(0.3, 0, 0), off_plane(0, 0, 0.3);
  EXPECT_NEAR(towards_edge.dot(apex * towards_edge), 1.0, 1e-12);
  EXPECT_NEAR(along_edge.dot(apex * along_edge), 0.0, 1e-12);
  EXPECT_NEAR(off_plane.dot(apex * off_plane), 0.0, 1e-12);
  EXPECT_TRUE(frame.sliver_stiffness[3].isZero());  // only in face 1, which is not listed
  // Corner 0's altitude is the distance to the line through 1 and 2.
  const Eigen::Vector3d e = (mesh.V.row(2) - mesh.V.row(1)).transpose().normalized();
  const Eigen::Vector3d to_line = -(Eigen::Vector3d(-1, 0, 0) - e * e.dot(Eigen::Vector3d(-1, 0, 0)));
  EXPECT_NEAR(to_line.dot(frame.sliver_stiffness[0] * to_line), 1.0, 1e-9);
}

TEST(EdgeMetric, HandComputedEdge) {
  // One triangle; every vertex has k1 = 2 along x and k2 = -0.5 along y (normal +z).
  Mesh mesh;
  mesh.V.resize(3, 3);
  mesh.V << 0, 0, 0, 3, 0, 0, 0, 4, 0;
  mesh.F.resize(1, 3);
  mesh.F << 0, 1, 2;
  const Topology topology = build_topology(mesh.F, 3);
  FlowFrame frame;
  frame.P = mesh.V;
  Curvature& c = frame.curvature;
  c.k1 = Eigen::VectorXd::Constant(3, 2.0);
  c.k2 = Eigen::VectorXd::Constant(3, -0.5);
  c.T1 = Vertices(3, 3);
  c.T2 = Vertices(3, 3);
  c.N = Vertices(3, 3);
  c.T1.rowwise() = Eigen::RowVector3d(1, 0, 0);
  c.T2.rowwise() = Eigen::RowVector3d(0, 1, 0);
  c.N.rowwise() = Eigen::RowVector3d(0, 0, 1);
  // Edges: (0,1) = (3,0,0): f = 2 * 9 = 18; (0,2) = (0,4,0): f = 0.5 * 16 = 8;
  // (1,2) = (-3,4,0): f = 2 * 9 + 0.5 * 16 = 26. F_em = (18 + 8 + 26) / 3.
  EXPECT_NEAR(edge_metric_energy(mesh.V, topology, frame), 52.0 / 3.0, 1e-12);
  // Eq. 6 at a displaced point: c1 = d|k1| / (d|k1| + 1) with d = 0.5: 0.5; c2 = 0.2.
  frame.d = 0.5;
  Vertices moved = mesh.V;
  moved.row(0) << 1, 1, 1;  // (v - p) = (1, 1, 1): h = 0.5 + 0.2 + 1
  EXPECT_NEAR(squared_distance_energy(moved, frame), (0.5 + 0.2 + 1.0) / 3.0, 1e-12);
  EXPECT_EQ(distance_coefficient(0.5, 0.0), 0.0);
}

}  // namespace
}  // namespace vertexflow
