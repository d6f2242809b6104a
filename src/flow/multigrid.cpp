#include "multigrid.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace vertexflow {
namespace {

using SparseMatrix = AdditiveMultilevel::SparseMatrix;
using Triplet = Eigen::Triplet<double>;

// Strength of connection between nodes (Vanek et al.): |A_kl|_F >= theta sqrt(|A_kk|_F |A_ll|_F).
// Weak couplings would glue aggregates across the anisotropy and are left out of the graph.
constexpr double kStrengthThreshold = 0.08;
// Power iterations for the spectral radius of D^-1 A in the prolongator's damping.
constexpr int kPowerIterations = 12;

// The strong-connection graph of A's 3x3 blocks, CSR.
void strength_graph(const SparseMatrix& A, std::vector<int>& start, std::vector<int>& neighbours) {
  const auto nodes = static_cast<int>(A.rows() / 3);
  // |A_kl|_F^2 of every stored block, row by row with a dense accumulator.
  std::vector<double> squared(static_cast<std::size_t>(nodes), 0.0), diagonal(static_cast<std::size_t>(nodes), 0.0);
  std::vector<int> touched;
  std::vector<std::vector<std::pair<int, double>>> blocks(static_cast<std::size_t>(nodes));
  for (int k = 0; k < nodes; ++k) {
    touched.clear();
    for (int c = 0; c < 3; ++c)
      for (SparseMatrix::InnerIterator it(A, 3 * k + c); it; ++it) {
        const auto l = static_cast<int>(it.col() / 3);
        if (squared[static_cast<std::size_t>(l)] == 0) touched.push_back(l);
        squared[static_cast<std::size_t>(l)] += it.value() * it.value() + 1e-300;  // touched, even if zero
      }
    auto& row = blocks[static_cast<std::size_t>(k)];
    row.reserve(touched.size());
    for (const int l : touched) {
      row.emplace_back(l, squared[static_cast<std::size_t>(l)]);
      squared[static_cast<std::size_t>(l)] = 0;
    }
    std::sort(row.begin(), row.end());
    for (const auto& [l, value] : row)
      if (l == k) diagonal[static_cast<std::size_t>(k)] = std::sqrt(value);
  }
  start.assign(static_cast<std::size_t>(nodes) + 1, 0);
  neighbours.clear();
  for (int k = 0; k < nodes; ++k) {
    for (const auto& [l, value] : blocks[static_cast<std::size_t>(k)]) {
      if (l == k) continue;
      const double bound = kStrengthThreshold * kStrengthThreshold * diagonal[static_cast<std::size_t>(k)] *
                           diagonal[static_cast<std::size_t>(l)];
      if (value >= bound) neighbours.push_back(l);
    }
    start[static_cast<std::size_t>(k) + 1] = static_cast<int>(neighbours.size());
  }
}

// The inverses of A's 3x3 diagonal blocks, as a block-diagonal matrix.
SparseMatrix block_diagonal_inverse(const SparseMatrix& A) {
  const Eigen::Index nodes = A.rows() / 3;
  std::vector<Triplet> triplets;
  triplets.reserve(static_cast<std::size_t>(9 * nodes));
  for (Eigen::Index k = 0; k < nodes; ++k) {
    Eigen::Matrix3d block = Eigen::Matrix3d::Zero();
    for (int c = 0; c < 3; ++c)
      for (SparseMatrix::InnerIterator it(A, 3 * k + c); it; ++it)
        if (it.col() / 3 == k) block(c, it.col() % 3) = it.value();
    const Eigen::Matrix3d inverse = block.inverse();
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) triplets.emplace_back(3 * k + r, 3 * k + c, inverse(r, c));
  }
  SparseMatrix D(A.rows(), A.cols());
  D.setFromTriplets(triplets.begin(), triplets.end());
  return D;
}

// Largest eigenvalue of D^-1 A (similar to a symmetric matrix), by power iteration from a
// fixed start.
double spectral_radius(const SparseMatrix& inverse_diagonal, const SparseMatrix& A) {
  Eigen::VectorXd v(A.rows());
  for (Eigen::Index k = 0; k < v.size(); ++k) v[k] = 1.0 + 0.5 * std::sin(0.7 * static_cast<double>(k));
  double lambda = 1;
  for (int iteration = 0; iteration < kPowerIterations; ++iteration) {
    Eigen::VectorXd w = inverse_diagonal * (A * v);
    lambda = w.norm() / v.norm();
    v = w / w.norm();
  }
  return lambda;
}

}  // namespace

std::vector<int> aggregate_nodes(const std::vector<int>& start, const std::vector<int>& neighbours,
                                 const std::vector<char>& excluded, int& count) {
  const auto nodes = static_cast<int>(start.size()) - 1;
  std::vector<int> aggregate(static_cast<std::size_t>(nodes), -1);
  auto ring = [&](int k) {
    return std::pair{neighbours.data() + start[static_cast<std::size_t>(k)],
                     neighbours.data() + start[static_cast<std::size_t>(k) + 1]};
  };
  auto usable = [&](int k) {
    return !excluded[static_cast<std::size_t>(k)] && aggregate[static_cast<std::size_t>(k)] < 0;
  };
  count = 0;
  // Phase 1: roots whose neighbours are all unaggregated.
  for (int root = 0; root < nodes; ++root) {
    if (!usable(root)) continue;
    const auto [begin, end] = ring(root);
    bool free = true;
    for (const int* l = begin; l != end && free; ++l) free = excluded[static_cast<std::size_t>(*l)] || usable(*l);
    if (!free) continue;
    aggregate[static_cast<std::size_t>(root)] = count;
    for (const int* l = begin; l != end; ++l)
      if (!excluded[static_cast<std::size_t>(*l)]) aggregate[static_cast<std::size_t>(*l)] = count;
    ++count;
  }
  // Phase 2: the rest join a nearest aggregate, breadth first from the aggregated nodes.
  std::vector<int> queue;
  for (int k = 0; k < nodes; ++k)
    if (aggregate[static_cast<std::size_t>(k)] >= 0) queue.push_back(k);
  auto spread = [&](std::size_t head) {
    for (; head < queue.size(); ++head) {
      const int k = queue[head];
      const auto [begin, end] = ring(k);
      for (const int* l = begin; l != end; ++l) {
        if (!usable(*l)) continue;
        aggregate[static_cast<std::size_t>(*l)] = aggregate[static_cast<std::size_t>(k)];
        queue.push_back(*l);
      }
    }
  };
  spread(0);
  // Phase 3: nodes not connected to any aggregate (isolated, or components without a root).
  for (int k = 0; k < nodes; ++k) {
    if (!usable(k)) continue;
    aggregate[static_cast<std::size_t>(k)] = count++;
    const std::size_t head = queue.size();
    queue.push_back(k);
    spread(head);
  }
  return aggregate;
}

AdditiveMultilevel::AdditiveMultilevel(SparseMatrix A, Eigen::Index coarsest_unknowns) {
  if (A.rows() != A.cols() || A.rows() % 3 != 0)
    throw std::invalid_argument("multilevel: the matrix must be square with 3 unknowns per node");
  A.makeCompressed();
  while (A.rows() > coarsest_unknowns) {
    std::vector<int> start, neighbours;
    strength_graph(A, start, neighbours);
    const auto nodes = static_cast<int>(A.rows() / 3);
    int count = 0;
    const std::vector<int> aggregate =
        aggregate_nodes(start, neighbours, std::vector<char>(static_cast<std::size_t>(nodes), 0), count);
    if (count == 0 || 3 * count > 0.8 * static_cast<double>(A.rows())) break;  // coarsening stalled
    // Tentative prolongator: the translations of each aggregate, columns of unit length.
    std::vector<int> size(static_cast<std::size_t>(count), 0);
    for (const int a : aggregate) ++size[static_cast<std::size_t>(a)];
    std::vector<Triplet> triplets;
    triplets.reserve(static_cast<std::size_t>(A.rows()));
    for (int k = 0; k < nodes; ++k) {
      const int a = aggregate[static_cast<std::size_t>(k)];
      const double scale = 1.0 / std::sqrt(static_cast<double>(size[static_cast<std::size_t>(a)]));
      for (int c = 0; c < 3; ++c) triplets.emplace_back(3 * k + c, 3 * a + c, scale);
    }
    SparseMatrix tentative(A.rows(), 3 * static_cast<Eigen::Index>(count));
    tentative.setFromTriplets(triplets.begin(), triplets.end());
    // P = (I - omega B A) P_tent with omega = 4 / (3 rho(B A)), the usual damping (it
    // minimises the prolongator's energy for the highest modes).
    Level level;
    level.block_inverse = block_diagonal_inverse(A);
    const double omega = 4.0 / (3.0 * spectral_radius(level.block_inverse, A));
    level.P = tentative - omega * SparseMatrix(level.block_inverse * SparseMatrix(A * tentative));
    level.P.prune(0.0);
    level.R = level.P.transpose();
    SparseMatrix coarse = level.R * SparseMatrix(A * level.P);
    levels_.push_back(std::move(level));
    A = std::move(coarse);
    A.makeCompressed();
  }
  coarsest_factor_.compute(Eigen::MatrixXd(A));
  if (coarsest_factor_.info() != Eigen::Success)
    throw std::runtime_error("multilevel: the coarsest matrix is not positive definite");
}

void AdditiveMultilevel::apply(const Eigen::VectorXd& b, Eigen::VectorXd& x) const {
  apply(0, b, x);
}

void AdditiveMultilevel::apply(std::size_t index, const Eigen::VectorXd& b, Eigen::VectorXd& x) const {
  if (index == levels_.size()) {
    x = coarsest_factor_.solve(b);
    return;
  }
  const Level& level = levels_[index];
  Eigen::VectorXd coarse;
  apply(index + 1, level.R * b, coarse);
  x = level.block_inverse * b;
  x += level.P * coarse;
}

}  // namespace vertexflow
