// The smoothed-aggregation pieces behind LinearSolver::Multilevel (src/flow/multigrid.h):
// aggregation of a graph, and the additive multilevel operator as a preconditioner of a
// bi-Laplacian, the operator whose slow modes it exists for.
#include "numerics/block3.h"
#include "numerics/multigrid.h"

#include <gtest/gtest.h>
#include <Eigen/QR>
#include <Eigen/Sparse>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <random>
#include <vector>

namespace vertexflow {
namespace {

// The 4-neighbour grid graph of side x side nodes, CSR.
struct Graph {
  std::vector<int> start, neighbours;
};
Graph grid_graph(int side) {
  Graph g;
  g.start.push_back(0);
  for (int y = 0; y < side; ++y)
    for (int x = 0; x < side; ++x) {
      if (x > 0) g.neighbours.push_back(y * side + x - 1);
      if (x + 1 < side) g.neighbours.push_back(y * side + x + 1);
      if (y > 0) g.neighbours.push_back((y - 1) * side + x);
      if (y + 1 < side) g.neighbours.push_back((y + 1) * side + x);
      g.start.push_back(static_cast<int>(g.neighbours.size()));
    }
  return g;
}

// Is every aggregate connected through nodes of the same aggregate?
bool aggregates_connected(const Graph& g, const std::vector<int>& aggregate, int count) {
  std::vector<char> seen(aggregate.size(), 0);
  int components = 0;
  for (std::size_t seed = 0; seed < aggregate.size(); ++seed) {
    if (aggregate[seed] < 0 || seen[seed]) continue;
    ++components;
    std::vector<int> queue{static_cast<int>(seed)};
    seen[seed] = 1;
    for (std::size_t head = 0; head < queue.size(); ++head)
      for (int k = g.start[static_cast<std::size_t>(queue[head])];
           k < g.start[static_cast<std::size_t>(queue[head]) + 1]; ++k) {
        const auto l = static_cast<std::size_t>(g.neighbours[static_cast<std::size_t>(k)]);
        if (!seen[l] && aggregate[l] == aggregate[seed]) {
          seen[l] = 1;
          queue.push_back(static_cast<int>(l));
        }
      }
  }
  return components == count;
}

TEST(Multigrid, AggregatesPartitionTheGraphIntoConnectedPieces) {
  const int side = 20;
  const Graph g = grid_graph(side);
  std::vector<char> excluded(side * side, 0);
  for (int x = 0; x < side; ++x) excluded[static_cast<std::size_t>(x)] = 1;  // a fixed boundary row
  int count = 0;
  const std::vector<int> aggregate = aggregate_nodes(g.start, g.neighbours, excluded, count);
  std::vector<int> size(static_cast<std::size_t>(count), 0);
  for (std::size_t k = 0; k < aggregate.size(); ++k) {
    if (excluded[k]) {
      EXPECT_EQ(aggregate[k], -1);
      continue;
    }
    ASSERT_GE(aggregate[k], 0);
    ASSERT_LT(aggregate[k], count);
    ++size[static_cast<std::size_t>(aggregate[k])];
  }
  EXPECT_TRUE(aggregates_connected(g, aggregate, count));
  // Roots take their 4 neighbours; the rest join: 380 nodes in 40-130 aggregates of 1-9 nodes.
  EXPECT_GE(count, 40);
  EXPECT_LE(count, 130);
  EXPECT_LE(*std::max_element(size.begin(), size.end()), 9);
  EXPECT_GE(*std::min_element(size.begin(), size.end()), 1);
}

TEST(Multigrid, IsolatedNodesGetTheirOwnAggregates) {
  const std::vector<int> start = {0, 1, 2, 2, 2};  // an edge 0-1, nodes 2 and 3 alone
  const std::vector<int> neighbours = {1, 0};
  int count = 0;
  const std::vector<int> aggregate = aggregate_nodes(start, neighbours, std::vector<char>(4, 0), count);
  EXPECT_EQ(count, 3);
  EXPECT_EQ(aggregate[0], aggregate[1]);
  EXPECT_NE(aggregate[2], aggregate[3]);
  EXPECT_NE(aggregate[2], aggregate[0]);
}

// (L^T L + shift I) (x) I_3 with L the grid's graph Laplacian and one edge of nodes tied to
// zero by an extra diagonal: a bi-Laplacian like F_smo's on a flat region, as 3x3 blocks; or,
// with `squared` false, (L + shift I) (x) I_3, a second-order operator.
BlockSparseMatrix grid_operator(int side, double shift, bool squared) {
  const Graph g = grid_graph(side);
  const int n = side * side;
  Eigen::SparseMatrix<double, Eigen::RowMajor> L(n, n);
  std::vector<Eigen::Triplet<double>> t;
  for (int k = 0; k < n; ++k) {
    const int degree = g.start[static_cast<std::size_t>(k) + 1] - g.start[static_cast<std::size_t>(k)];
    t.emplace_back(k, k, degree);
    for (int m = g.start[static_cast<std::size_t>(k)]; m < g.start[static_cast<std::size_t>(k) + 1]; ++m)
      t.emplace_back(k, g.neighbours[static_cast<std::size_t>(m)], -1.0);
  }
  L.setFromTriplets(t.begin(), t.end());
  Eigen::SparseMatrix<double, Eigen::RowMajor> B =
      squared ? Eigen::SparseMatrix<double, Eigen::RowMajor>(L.transpose() * L) : L;
  for (int k = 0; k < n; ++k) B.coeffRef(k, k) += shift + (k < side ? 1.0 : 0.0);
  B.makeCompressed();
  BlockSparseMatrix A;
  A.rows = A.cols = n;
  for (int r = 0; r < n; ++r) {
    for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(B, r); it; ++it) {
      A.column.push_back(static_cast<int>(it.col()));
      A.block.push_back(it.value() * Eigen::Matrix3d::Identity());
    }
    A.start.push_back(static_cast<int>(A.column.size()));
  }
  return A;
}

BlockSparseMatrix bilaplacian(int side, double shift) {
  return grid_operator(side, shift, true);
}

// Preconditioned conjugate gradients from 0 until |r| <= 1e-8 |b|; returns the iterations.
template <class Preconditioner>
int pcg_iterations(const BlockSparseMatrix& A, const Eigen::VectorXd& b, Preconditioner&& M) {
  Eigen::VectorXd x = Eigen::VectorXd::Zero(b.size()), r = b, z, p, Ap;
  M(r, z);
  p = z;
  double rz = r.dot(z);
  for (int iteration = 1; iteration <= 20000; ++iteration) {
    A.multiply(p, Ap);
    const double alpha = rz / p.dot(Ap);
    x += alpha * p;
    r -= alpha * Ap;
    if (r.norm() <= 1e-8 * b.norm()) return iteration;
    M(r, z);
    const double next = r.dot(z);
    p = z + (next / rz) * p;
    rz = next;
  }
  return 20000;
}

TEST(Multigrid, AdditiveMultilevelIsASymmetricPositivePreconditioner) {
  const BlockSparseMatrix A = bilaplacian(40, 1e-6);
  const AdditiveMultilevel M(A);
  EXPECT_GE(M.num_levels(), 3);  // 4,800 unknowns coarsened to at most 240
  EXPECT_LE(M.coarsest_unknowns(), 240);
  std::mt19937 random(7);
  std::normal_distribution<double> normal;
  Eigen::VectorXd u(3 * A.rows), v(3 * A.rows), Mu, Mv;
  for (Eigen::Index k = 0; k < u.size(); ++k) {
    u[k] = normal(random);
    v[k] = normal(random);
  }
  M.apply(u, Mu);
  M.apply(v, Mv);
  EXPECT_NEAR(u.dot(Mv), v.dot(Mu), 1e-10 * std::abs(u.dot(Mv)) + 1e-12);
  EXPECT_GT(u.dot(Mu), 0);
  EXPECT_GT(v.dot(Mv), 0);
}

// D^T A D for a block diagonal D of random, well-conditioned 3x3 blocks: still symmetric positive
// definite, but its off-diagonal blocks D_k^T A_kl D_l are not symmetric, so that a lower block
// read without its transpose would show.
BlockSparseMatrix congruent(const BlockSparseMatrix& A, unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> entry(-0.3, 0.3);
  std::vector<Eigen::Matrix3d> D(static_cast<std::size_t>(A.rows));
  for (Eigen::Matrix3d& d : D)
    d = Eigen::Matrix3d::Identity() + Eigen::Matrix3d::NullaryExpr([&] { return entry(random); });
  BlockSparseMatrix C = A;
  for (int k = 0; k < A.rows; ++k)
    for (int m = A.start[static_cast<std::size_t>(k)]; m < A.start[static_cast<std::size_t>(k) + 1]; ++m)
      C.block[static_cast<std::size_t>(m)] = D[static_cast<std::size_t>(k)].transpose() *
                                             A.block[static_cast<std::size_t>(m)] *
                                             D[static_cast<std::size_t>(A.column[static_cast<std::size_t>(m)])];
  return C;
}

// A with each block below the diagonal replaced by the transpose of its mirror above (the
// congruence rounds the two halves differently), found by a plain search: a reference that
// does not go through the library's symmetric_from_upper.
BlockSparseMatrix exactly_symmetric(BlockSparseMatrix A) {
  for (int k = 0; k < A.rows; ++k)
    for (int m = A.start[static_cast<std::size_t>(k)]; m < A.start[static_cast<std::size_t>(k) + 1]; ++m) {
      const int c = A.column[static_cast<std::size_t>(m)];
      if (c >= k) continue;
      for (int q = A.start[static_cast<std::size_t>(c)]; q < A.start[static_cast<std::size_t>(c) + 1]; ++q)
        if (A.column[static_cast<std::size_t>(q)] == k)
          A.block[static_cast<std::size_t>(m)] = A.block[static_cast<std::size_t>(q)].transpose();
    }
  return A;
}

BlockSparseMatrix upper_half(const BlockSparseMatrix& A) {
  BlockSparseMatrix U;
  U.rows = U.cols = A.rows;
  for (int k = 0; k < A.rows; ++k) {
    for (int m = A.start[static_cast<std::size_t>(k)]; m < A.start[static_cast<std::size_t>(k) + 1]; ++m)
      if (A.column[static_cast<std::size_t>(m)] >= k) {
        U.column.push_back(A.column[static_cast<std::size_t>(m)]);
        U.block.push_back(A.block[static_cast<std::size_t>(m)]);
      }
    U.start.push_back(static_cast<int>(U.column.size()));
  }
  return U;
}

TEST(Multigrid, TheUpperHalfGivesTheSameHierarchy) {
  // The flow hands its first coarse matrix over as its upper half (the set-up's largest matrix,
  // not copied whole). The hierarchy must be the same bytes: M u equal to the last bit, for a
  // matrix that coarsens over several levels, one already at the coarsest size, and one whose
  // coarsening stalls at once; with smoothed and with tentative prolongators (whose Galerkin
  // product has its own code).
  for (const auto prolongators :
       {AdditiveMultilevel::Prolongators::Smoothed, AdditiveMultilevel::Prolongators::Tentative}) {
    auto expect_same = [prolongators](const BlockSparseMatrix& A, int coarsest_unknowns) {
      const AdditiveMultilevel whole(A, AdditiveMultilevel::Storage::Whole, coarsest_unknowns, prolongators);
      const AdditiveMultilevel upper(upper_half(A), AdditiveMultilevel::Storage::UpperHalf, coarsest_unknowns,
                                     prolongators);
      EXPECT_EQ(whole.num_levels(), upper.num_levels());
      EXPECT_EQ(whole.coarsest_unknowns(), upper.coarsest_unknowns());
      std::mt19937 random(3);
      std::normal_distribution<double> normal;
      Eigen::VectorXd u(3 * A.rows), Mu_whole, Mu_upper;
      for (Eigen::Index k = 0; k < u.size(); ++k) u[k] = normal(random);
      whole.apply(u, Mu_whole);
      upper.apply(u, Mu_upper);
      EXPECT_TRUE(Mu_whole == Mu_upper) << "largest difference " << (Mu_whole - Mu_upper).cwiseAbs().maxCoeff();
    };
    const BlockSparseMatrix A = exactly_symmetric(congruent(bilaplacian(24, 1e-6), 5));
    expect_same(A, 240);
    expect_same(A, 3 * A.rows);  // no coarse level: factored whole
    BlockSparseMatrix diagonal;  // no strong connection: coarsening stalls on the first level
    diagonal.rows = diagonal.cols = 600;
    for (int k = 0; k < diagonal.rows; ++k) {
      diagonal.column.push_back(k);
      diagonal.block.push_back((1.0 + 0.1 * (k % 5)) * Eigen::Matrix3d::Identity());
      diagonal.start.push_back(k + 1);
    }
    expect_same(diagonal, 240);
    {
      const AdditiveMultilevel M(upper_half(diagonal), AdditiveMultilevel::Storage::UpperHalf, 240, prolongators);
      EXPECT_EQ(M.num_levels(), 1);
      EXPECT_FALSE(M.coarsest_factored());
    }
  }
}

TEST(Multigrid, CutsTheIterationsOfABiLaplacian) {
  // Block-Jacobi's count grows like the side squared on a bi-Laplacian; the multilevel
  // operator's grows much more slowly (measured here: 1,733 against 478 with the truncated
  // prolongators, 495 without; on fandisk, with the flow solver's smoothed fine level on top,
  // 1,124 against 162).
  const BlockSparseMatrix A = bilaplacian(40, 1e-6);
  const AdditiveMultilevel M(A);
  Eigen::VectorXd b(3 * A.rows);
  for (Eigen::Index k = 0; k < b.size(); ++k) b[k] = std::sin(0.01 * static_cast<double>(k)) + 0.1;
  Eigen::VectorXd inverse_diagonal(3 * A.rows);
  for (int k = 0; k < A.rows; ++k)
    for (int m = A.start[static_cast<std::size_t>(k)]; m < A.start[static_cast<std::size_t>(k) + 1]; ++m)
      if (A.column[static_cast<std::size_t>(m)] == k)
        inverse_diagonal.segment<3>(3 * k) = A.block[static_cast<std::size_t>(m)].diagonal().cwiseInverse();
  const int jacobi =
      pcg_iterations(A, b, [&](const Eigen::VectorXd& r, Eigen::VectorXd& z) { z = inverse_diagonal.cwiseProduct(r); });
  const int multilevel = pcg_iterations(A, b, [&](const Eigen::VectorXd& r, Eigen::VectorXd& z) { M.apply(r, z); });
  EXPECT_LT(multilevel, 20000);
  EXPECT_LT(3 * multilevel, jacobi) << "multilevel " << multilevel << ", Jacobi " << jacobi;
}

TEST(Multigrid, SmoothedProlongatorsCutTheIterationsOfScalarGridOperators) {
  // Piecewise-constant coarse functions have a large energy at aggregate borders; one smoothing
  // step removes most of it. Measured here (smoothed, tentative): the bi-Laplacian 478, 919; the
  // second-order grid operator 36, 148. (On the flow's curved surfaces the tentative ones take
  // fewer: FlowSolver.HierarchyIsSmoothedWherePlanarRegionsNeedIt.)
  auto iterations = [](const BlockSparseMatrix& A, AdditiveMultilevel::Prolongators prolongators) {
    const AdditiveMultilevel M(A, AdditiveMultilevel::Storage::Whole, AdditiveMultilevel::kCoarsestUnknowns,
                               prolongators);
    Eigen::VectorXd b(3 * A.rows);
    for (Eigen::Index k = 0; k < b.size(); ++k) b[k] = std::sin(0.01 * static_cast<double>(k)) + 0.1;
    return pcg_iterations(A, b, [&](const Eigen::VectorXd& r, Eigen::VectorXd& z) { M.apply(r, z); });
  };
  using P = AdditiveMultilevel::Prolongators;
  for (const auto& [A, name] :
       {std::pair{bilaplacian(40, 1e-6), "bi-Laplacian"}, std::pair{grid_operator(80, 1e-6, false), "second order"}}) {
    const int smoothed = iterations(A, P::Smoothed), tentative = iterations(A, P::Tentative);
    EXPECT_LT(1.5 * smoothed, tentative) << name << ": smoothed " << smoothed << ", tentative " << tentative;
    EXPECT_LT(tentative, 20000) << name;  // converges, more slowly
  }
}

TEST(Multigrid, TruncatedProlongatorKeepsTheTranslations) {
  // On the grid bi-Laplacian (wide rows: a node's 2-ring reaches several aggregates) with one
  // damped Jacobi step: truncation must drop blocks and still map every coarse translation
  // (c_a = sqrt(|a|) t) to (I - omega B A) t, as the untruncated prolongator does.
  const int side = 16;
  const BlockSparseMatrix A = bilaplacian(side, 1e-6);
  const Graph g = grid_graph(side);
  int count = 0;
  const std::vector<int> aggregate =
      aggregate_nodes(g.start, g.neighbours, std::vector<char>(static_cast<std::size_t>(A.rows), 0), count);
  std::vector<Eigen::Matrix3d> inverse(static_cast<std::size_t>(A.rows));
  for (int k = 0; k < A.rows; ++k)
    for (int m = A.start[static_cast<std::size_t>(k)]; m < A.start[static_cast<std::size_t>(k) + 1]; ++m)
      if (A.column[static_cast<std::size_t>(m)] == k)
        inverse[static_cast<std::size_t>(k)] = A.block[static_cast<std::size_t>(m)].inverse();
  const double omega = 0.2;
  const BlockSparseMatrix full = smoothed_prolongator(A, aggregate, count, inverse, omega, 0.0);
  const BlockSparseMatrix truncated = smoothed_prolongator(A, aggregate, count, inverse, omega, 0.1);
  // Measured: 398 of 1,088 blocks kept; at most two thirds.
  EXPECT_LT(3 * truncated.block.size(), 2 * full.block.size());

  std::vector<int> members(static_cast<std::size_t>(count), 0);
  for (const int a : aggregate) ++members[static_cast<std::size_t>(a)];
  const Eigen::Vector3d t(1.0, -2.0, 0.5);
  Eigen::VectorXd coarse(3 * count), fine(3 * A.rows), expected, full_image, truncated_image;
  for (int a = 0; a < count; ++a) coarse.segment<3>(3 * a) = std::sqrt(members[static_cast<std::size_t>(a)]) * t;
  for (int k = 0; k < A.rows; ++k) fine.segment<3>(3 * k) = t;
  A.multiply(fine, expected);  // (I - omega B A) t
  for (int k = 0; k < A.rows; ++k)
    expected.segment<3>(3 * k) = t - omega * inverse[static_cast<std::size_t>(k)] * expected.segment<3>(3 * k);
  full.multiply(coarse, full_image);
  truncated.multiply(coarse, truncated_image);
  EXPECT_LT((full_image - expected).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT((truncated_image - expected).cwiseAbs().maxCoeff(), 1e-12);

  // What is left is the own aggregate's block and blocks at least a tenth of the row's largest.
  for (int k = 0; k < truncated.rows; ++k) {
    double largest = 0;
    for (int m = full.start[static_cast<std::size_t>(k)]; m < full.start[static_cast<std::size_t>(k) + 1]; ++m)
      largest = std::max(largest, full.block[static_cast<std::size_t>(m)].norm());
    for (int m = truncated.start[static_cast<std::size_t>(k)]; m < truncated.start[static_cast<std::size_t>(k) + 1];
         ++m) {
      if (truncated.column[static_cast<std::size_t>(m)] != aggregate[static_cast<std::size_t>(k)]) {
        EXPECT_GE(truncated.block[static_cast<std::size_t>(m)].norm(), 0.1 * largest);
      }
    }
  }
}

// Thousands of separate components (scan debris, a soup of parts): each is one node after the
// first coarsening, the next level has no strong couplings and coarsening stalls with 30,000
// nodes. A dense factor of that level would take 65 GB; the block-Jacobi inverse that replaces
// it keeps M symmetric positive definite and, since the level is block diagonal, exact there.
TEST(BlockJacobi, FloatFactorKeepsAnAnisotropicInversePositiveDefinite) {
  // Block-Jacobi's inverses are stored as float factors, B = M^T M (block3.h). On blocks more
  // anisotropic than the flow's (stiff along a normal n, soft in the tangent plane; 1e12 against
  // 1, in random frames) n^T B n, the stiff direction's 1e-12, must stay positive and about
  // right, where an entry-wise rounded inverse (Sym3f) errs by 1e-8 (measured 1.2e-8), four
  // orders more. B r is the inverse's product to float accuracy at 1e6 against 1 (measured
  // 4.8e-7; at 1e12 double's own Cholesky loses 1e-4 to cancellation).
  std::mt19937 random(13);
  std::normal_distribution<double> normal;
  double worst_stiff = 1, worst_product = 0, worst_rounded = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Matrix3d Q =
        Eigen::Matrix3d::NullaryExpr([&] { return normal(random); }).householderQr().householderQ();
    auto frame_block = [&](double stiff) {
      const Eigen::Vector3d stiffness(stiff, 1.0 + 0.5 * (trial % 3), 1.0);
      return std::pair{Eigen::Matrix3d(Q * stiffness.asDiagonal() * Q.transpose()),
                       Eigen::Matrix3d(Q * stiffness.cwiseInverse().asDiagonal() * Q.transpose())};
    };
    const auto [block, inverse] = frame_block(1e12);
    const InverseFactor3f B = InverseFactor3f::of_inverse(block);
    const Eigen::Vector3d n = Q.col(0);
    worst_stiff = std::min(worst_stiff, std::min(n.dot(B * n) / 1e-12, 1e-12 / n.dot(B * n)));
    worst_rounded = std::max(worst_rounded, std::abs(n.dot(Sym3f(inverse) * n) - 1e-12));
    const auto [moderate, moderate_inverse] = frame_block(1e6);
    const Eigen::Vector3d r(normal(random), normal(random), normal(random));
    worst_product = std::max(worst_product, (InverseFactor3f::of_inverse(moderate) * r - moderate_inverse * r).norm() /
                                                (moderate_inverse * r).norm());
  }
  std::cout << "[measured] n^T B n within a factor " << 1 / worst_stiff << " of 1e-12; product error " << worst_product
            << "; rounded inverse's n^T B n error " << worst_rounded << "\n";
  EXPECT_GT(worst_stiff, 0.5);
  EXPECT_LT(worst_product, 1.5e-6);
  // The scalar form (the fit's block-Jacobi) and a block that is not positive definite.
  EXPECT_TRUE((InverseFactor3f::scalar(0.25) * Eigen::Vector3d(4, 8, -4)).isApprox(Eigen::Vector3d(1, 2, -1), 1e-6));
  const InverseFactor3f fallback = InverseFactor3f::of_inverse(Eigen::Vector3d(2.0, 1.0, -0.5).asDiagonal());
  EXPECT_TRUE((fallback * Eigen::Vector3d(1, 1, 1)).isApprox(Eigen::Vector3d(1.2, 1.2, 1.2), 1e-6));  // 3 / trace
}

TEST(Multigrid, StalledCoarseningOnManyComponentsStaysLinear) {
  constexpr int kComponents = 30000, kPath = 4;
  BlockSparseMatrix A;
  A.rows = A.cols = kComponents * kPath;
  for (int c = 0; c < kComponents; ++c)
    for (int k = 0; k < kPath; ++k) {  // a path's Laplacian plus a small shift, per component
      const int node = c * kPath + k;
      const double scale = 1.0 + 0.01 * (c % 7);
      if (k > 0) A.column.push_back(node - 1), A.block.push_back(-scale * Eigen::Matrix3d::Identity());
      A.column.push_back(node), A.block.push_back((2.01 * scale) * Eigen::Matrix3d::Identity());
      if (k + 1 < kPath) A.column.push_back(node + 1), A.block.push_back(-scale * Eigen::Matrix3d::Identity());
      A.start.push_back(static_cast<int>(A.column.size()));
    }
  const AdditiveMultilevel M(A);
  EXPECT_EQ(M.coarsest_unknowns(), 3 * kComponents);  // one node per component, then stalled
  EXPECT_FALSE(M.coarsest_factored());
  std::mt19937 random(11);
  std::normal_distribution<double> normal;
  Eigen::VectorXd u(3 * A.rows), v(3 * A.rows), Mu, Mv;
  for (Eigen::Index k = 0; k < u.size(); ++k) u[k] = normal(random), v[k] = normal(random);
  M.apply(u, Mu);
  M.apply(v, Mv);
  EXPECT_NEAR(u.dot(Mv), v.dot(Mu), 1e-10 * std::abs(u.dot(Mv)));
  EXPECT_GT(u.dot(Mu), 0);
  // A preconditioner still: conjugate gradients converge (measured: 4 iterations).
  const int iterations = pcg_iterations(A, u, [&](const Eigen::VectorXd& r, Eigen::VectorXd& z) { M.apply(r, z); });
  std::cout << "[measured] " << iterations << " iterations\n";
  EXPECT_LE(iterations, 10);
}

}  // namespace
}  // namespace vertexflow
