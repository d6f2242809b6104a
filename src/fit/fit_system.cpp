// The fit's linear system and its two solvers (fit_system.h).
#include "fit_system.h"

#include "numerics/block3.h"
#include "numerics/conjugate_gradients.h"
#include "numerics/parallel.h"
#include "numerics/sparse_cholesky.h"

#include <Eigen/SparseCore>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <span>
#include <stdexcept>

namespace vertexflow {

using SparseMatrix = Eigen::SparseMatrix<double>;
using Triplet = Eigen::Triplet<double>;

namespace {

// The uniform Laplacian L (n x n): (L x)_i = x_i - mean of x over i's ring.
SparseMatrix uniform_laplacian(const Topology& topology, Index n) {
  std::vector<Triplet> entries;
  for (Index i = 0; i < n; ++i) {
    const auto v = static_cast<std::size_t>(i);
    const Index begin = topology.ring_offsets[v], end = topology.ring_offsets[v + 1];
    if (begin == end) continue;
    entries.emplace_back(i, i, 1.0);
    const double w = -1.0 / static_cast<double>(end - begin);
    for (Index k = begin; k < end; ++k) entries.emplace_back(i, topology.ring_vertices[static_cast<std::size_t>(k)], w);
  }
  SparseMatrix L(n, n);
  L.setFromTriplets(entries.begin(), entries.end());
  return L;
}

// The data rows with their direction's normalisation (fit.h: 1 / N_S for the reference's
// samples, w_v / N_M for the mesh's points): fn(row, weight) for each.
template <class Fn>
void for_each_weighted_row(const std::vector<DataRow>& to_mesh, const std::vector<DataRow>& to_reference,
                           const FitOptions& options, Fn&& fn) {
  auto total_weight = [](const std::vector<DataRow>& rows) {
    double sum = 0;
    for (const DataRow& row : rows) sum += row.weight;
    return sum;
  };
  if (!to_mesh.empty()) {
    const double w_mesh = 1.0 / total_weight(to_mesh);
    for (const DataRow& row : to_mesh) fn(row, w_mesh * row.weight);
  }
  if (!to_reference.empty()) {
    const double w_reference = options.mesh_to_reference_weight / total_weight(to_reference);
    for (const DataRow& row : to_reference) fn(row, w_reference * row.weight);
  }
}

// The n x n system of one round, with three right-hand sides (x, y, z), on a pattern fixed
// for all rounds: every round's matrix is L^T L, every face's corner pairs (stored even where
// a round puts no sample) and the diagonal, over the free vertices. Every data row lies in one
// face (or is one vertex), so a round adds its rows into precomputed slots of the values
// array, and CHOLMOD (sparse_cholesky.h: supernodal, exact, deterministic) reuses its ordering
// and symbolic analysis. Measured on bench_fit (10k vertices): assembling triplets and
// Eigen's simplicial LDL^T took 186 ms per round; this takes about a fifth of that.
class DirectFitSystem final : public FitSystem {
 public:
  DirectFitSystem(const Faces& F, const Topology& topology, const std::vector<char>& fixed, double fairness) {
    const auto n = static_cast<Index>(fixed.size());
    // Without fairness the pattern is the faces' alone, whose factor fills in far less than with
    // the anchored Laplacian's two-rings.
    const SparseMatrix L = fairness > 0 ? uniform_laplacian(topology, n) : SparseMatrix(n, n);
    const SparseMatrix laplacian_normal = SparseMatrix(L.transpose()) * L;
    unknown_.assign(static_cast<std::size_t>(n), -1);
    for (Index i = 0; i < n; ++i)
      if (!fixed[static_cast<std::size_t>(i)]) unknown_[static_cast<std::size_t>(i)] = free_count_++;
    // Upper-half pattern by columns: rows r <= c.
    std::vector<std::vector<std::int32_t>> columns(static_cast<std::size_t>(free_count_));
    auto add = [&](Index a, Index b) {
      const Index r = unknown_[static_cast<std::size_t>(a)], c = unknown_[static_cast<std::size_t>(b)];
      if (r >= 0 && c >= 0 && r <= c) columns[static_cast<std::size_t>(c)].push_back(static_cast<std::int32_t>(r));
    };
    for (Index i = 0; i < n; ++i) add(i, i);
    for (Index col = 0; col < laplacian_normal.outerSize(); ++col)
      for (SparseMatrix::InnerIterator it(laplacian_normal, col); it; ++it) add(it.row(), col);
    for (Index f = 0; f < F.rows(); ++f)
      for (int k = 0; k < 3; ++k)
        for (int l = 0; l < 3; ++l) add(F(f, k), F(f, l));
    column_start_.assign(static_cast<std::size_t>(free_count_) + 1, 0);
    std::vector<std::int32_t> rows;
    for (Index c = 0; c < free_count_; ++c) {
      auto& column = columns[static_cast<std::size_t>(c)];
      std::sort(column.begin(), column.end());
      column.erase(std::unique(column.begin(), column.end()), column.end());
      rows.insert(rows.end(), column.begin(), column.end());
      column_start_[static_cast<std::size_t>(c) + 1] = static_cast<std::int64_t>(rows.size());
    }
    rows_.assign(rows.begin(), rows.end());
    ordering_ = cholesky_.order(column_start_, rows);
    // Slots: the L^T L entries, and per face the slot of each corner pair (k, l) whose free
    // row is <= its free column (-1 otherwise, or where a corner is fixed).
    std::vector<Triplet> free_entries;
    for (Index col = 0; col < laplacian_normal.outerSize(); ++col)
      for (SparseMatrix::InnerIterator it(laplacian_normal, col); it; ++it) {
        const Index r = unknown_[static_cast<std::size_t>(it.row())], c = unknown_[static_cast<std::size_t>(col)];
        if (r >= 0 && c >= 0) free_entries.emplace_back(r, c, it.value());
        const std::int64_t at = slot(it.row(), col);
        if (at >= 0) laplacian_.emplace_back(at, it.value());
      }
    laplacian_free_.resize(free_count_, free_count_);
    laplacian_free_.setFromTriplets(free_entries.begin(), free_entries.end());
    face_slots_.resize(static_cast<std::size_t>(9 * F.rows()));
    for (Index f = 0; f < F.rows(); ++f)
      for (int k = 0; k < 3; ++k)
        for (int l = 0; l < 3; ++l) face_slots_[static_cast<std::size_t>(9 * f + 3 * k + l)] = slot(F(f, k), F(f, l));
  }

  Vertices solve(const Vertices& X, const std::vector<DataRow>& to_mesh, const std::vector<DataRow>& to_reference,
                 const FitOptions& options, FitReport& /*report*/) override {
    const Index n = X.rows();
    Vertices X_out = X;
    if (free_count_ == 0) return X_out;
    SparseCholesky::UpperMatrix A = cholesky_.allocate_upper(column_start_);
    std::copy(rows_.begin(), rows_.end(), A.rows().begin());
    std::span<double> values = A.values();
    std::fill(values.begin(), values.end(), 0.0);
    Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(free_count_, 3);
    // Adds w |sum_k b_k x_{i_k} - t|^2 for a row of face f (or of one vertex, f = -1): the free
    // corners go to the matrix, the fixed ones to the right-hand side.
    for_each_weighted_row(to_mesh, to_reference, options, [&](const DataRow& row, double w) {
      Eigen::Vector3d t = row.target;
      for (int k = 0; k < 3; ++k) {
        if (unknown_[static_cast<std::size_t>(row.corners[k])] < 0 && row.weights[k] != 0)
          t -= row.weights[k] * X.row(row.corners[k]).transpose();
      }
      for (int k = 0; k < 3; ++k) {
        const Index r = unknown_[static_cast<std::size_t>(row.corners[k])];
        if (r < 0 || row.weights[k] == 0) continue;
        rhs.row(r) += w * row.weights[k] * t.transpose();
        if (row.face < 0) {
          values[static_cast<std::size_t>(diagonal_slot(r))] += w * row.weights[k] * row.weights[k];
          continue;
        }
        for (int l = 0; l < 3; ++l) {
          const std::int64_t at = face_slots_[static_cast<std::size_t>(9 * row.face + 3 * k + l)];
          if (at >= 0) values[static_cast<std::size_t>(at)] += w * row.weights[k] * row.weights[l];
        }
      }
    });
    // w_f / n |L (x - x_k)|^2: matrix (w_f / n) L^T L, right-hand side (w_f / n) L^T L x_k over
    // the free vertices (the fixed columns cancel against the same columns moved to the right).
    const double w_fair = options.fairness / static_cast<double>(n);
    for (const auto& [at, value] : laplacian_) values[static_cast<std::size_t>(at)] += w_fair * value;
    Eigen::MatrixXd free_X(free_count_, 3);
    for (Index i = 0; i < n; ++i)
      if (unknown_[static_cast<std::size_t>(i)] >= 0) free_X.row(unknown_[static_cast<std::size_t>(i)]) = X.row(i);
    rhs += w_fair * (laplacian_free_ * free_X);
    // w_p / n |x - x_k|^2.
    const double w_stay = options.proximity / static_cast<double>(n);
    for (Index r = 0; r < free_count_; ++r) values[static_cast<std::size_t>(diagonal_slot(r))] += w_stay;
    rhs += w_stay * free_X;
    cholesky_.factorize(A, ordering_.permutation);
    for (int d = 0; d < 3; ++d) {
      const Eigen::VectorXd x = cholesky_.solve(rhs.col(d));
      for (Index i = 0; i < n; ++i) {
        const Index r = unknown_[static_cast<std::size_t>(i)];
        if (r >= 0) X_out(i, d) = x[r];
      }
    }
    return X_out;
  }

 private:
  // The position of (free row of a, free column of b) in the values array, or -1.
  std::int64_t slot(Index a, Index b) const {
    const Index r = unknown_[static_cast<std::size_t>(a)], c = unknown_[static_cast<std::size_t>(b)];
    if (r < 0 || c < 0 || r > c) return -1;
    const auto first = rows_.begin() + column_start_[static_cast<std::size_t>(c)];
    const auto last = rows_.begin() + column_start_[static_cast<std::size_t>(c) + 1];
    return static_cast<std::int64_t>(std::lower_bound(first, last, r) - rows_.begin());
  }
  // Rows are sorted and the diagonal is in every column: it is the column's last entry.
  std::int64_t diagonal_slot(Index r) const { return column_start_[static_cast<std::size_t>(r) + 1] - 1; }
  SparseMatrix laplacian_free_;  // L^T L over the free vertices
  std::vector<Index> unknown_;
  Index free_count_ = 0;
  std::vector<std::int64_t> column_start_;
  std::vector<std::int64_t> rows_;
  std::vector<std::pair<std::int64_t, double>> laplacian_;
  std::vector<std::int64_t> face_slots_;
  SparseCholesky cholesky_;
  SparseCholesky::Ordering ordering_;
};

// The same energy solved for the step d = x - X by conjugate gradients (fit_system.h):
//   (D + w_f / n L^T L + w_p / n I) d = b,   b_i = sum over rows w b_k (t - sum_l b_l X_l)
// over the free vertices, d = 0 at the fixed ones. The anchored Laplacian's and the proximity
// terms vanish from b (both are anchored at X). D, the data rows' matrix, is kept on the one-ring
// pattern (the diagonal first in each row, then the ring); L^T L is applied as L then L^T, which
// keeps the two-ring pattern (19 entries a row against 7) out of memory. The blocks of the
// unknowns are a vertex's x, y, z, which share one scalar matrix.
class IterativeFitSystem final : public FitSystem, BlockOperator {
 public:
  IterativeFitSystem(const Faces& F, const Topology& topology, const std::vector<char>& fixed,
                     const FitOptions& options)
      : F_(F), topology_(topology), fixed_(fixed), n_(static_cast<Index>(fixed.size())) {
    row_start_.resize(static_cast<std::size_t>(n_) + 1);
    row_start_[0] = 0;
    for (Index i = 0; i < n_; ++i)
      row_start_[static_cast<std::size_t>(i) + 1] = row_start_[static_cast<std::size_t>(i)] + 1 + topology.valence(i);
    if (row_start_.back() > std::numeric_limits<std::int32_t>::max())
      throw std::length_error("fit: the linear system has more than 2^31 entries");
    columns_.resize(static_cast<std::size_t>(row_start_.back()));
    parallel_for_index(n_, [&](Index i) {
      auto at = static_cast<std::size_t>(row_start_[static_cast<std::size_t>(i)]);
      columns_[at++] = i;
      const auto [begin, end] = topology.ring(i);
      for (const Index* j = begin; j != end; ++j) columns_[at++] = *j;
    });
    // The slot of each face's corner pair (k, l), k != l, in row F(f, k): 6 a face.
    face_slots_.resize(static_cast<std::size_t>(6 * F.rows()));
    parallel_for_index(static_cast<Index>(F.rows()), [&](Index f) {
      int pair = 0;
      for (int k = 0; k < 3; ++k)
        for (int l = 0; l < 3; ++l) {
          if (k == l) continue;
          face_slots_[static_cast<std::size_t>(6 * f + pair++)] = find_slot(F(f, k), F(f, l));
        }
    });
    if (options.fairness > 0) {
      inverse_valence_.resize(static_cast<std::size_t>(n_));
      parallel_for_index(n_, [&](Index i) {
        const Index valence = topology.valence(i);
        inverse_valence_[static_cast<std::size_t>(i)] = valence > 0 ? 1.0 / static_cast<double>(valence) : 0.0;
      });
    }
  }

  Vertices solve(const Vertices& X, const std::vector<DataRow>& to_mesh, const std::vector<DataRow>& to_reference,
                 const FitOptions& options, FitReport& report) override {
    values_.assign(columns_.size(), 0.0);
    BlockVector b = BlockVector::Zero(3 * static_cast<Eigen::Index>(n_));
    auto is_free = [&](Index v) { return !fixed_[static_cast<std::size_t>(v)]; };
    // D and b, row by row (serial: rows of many faces add into one vertex's entries).
    for_each_weighted_row(to_mesh, to_reference, options, [&](const DataRow& row, double w) {
      Eigen::Vector3d residual = row.target;
      const int corners = row.face < 0 ? 1 : 3;
      for (int k = 0; k < corners; ++k) residual -= row.weights[k] * X.row(row.corners[k]).transpose();
      for (int k = 0; k < corners; ++k) {
        const Index i = row.corners[k];
        if (!is_free(i) || row.weights[k] == 0) continue;
        block_at(b, i) += w * row.weights[k] * residual;
        values_[static_cast<std::size_t>(row_start_[static_cast<std::size_t>(i)])] +=
            w * row.weights[k] * row.weights[k];
        if (row.face < 0) continue;
        for (int l = 0; l < 3; ++l) {
          if (l == k || !is_free(row.corners[l])) continue;
          values_[static_cast<std::size_t>(face_slots_[static_cast<std::size_t>(6 * row.face + pair_index(k, l))])] +=
              w * row.weights[k] * row.weights[l];
        }
      }
    });
    w_fair_ = options.fairness / static_cast<double>(n_);
    w_stay_ = options.proximity / static_cast<double>(n_);
    // Block-Jacobi: the diagonal of the whole matrix, (L^T L)_ii = L_ii^2 + sum over the ring
    // of 1 / valence_k^2.
    std::vector<InverseFactor3f> inverse(static_cast<std::size_t>(n_));
    parallel_for_index(n_, [&](Index i) {
      if (!is_free(i)) return;
      double diagonal = values_[static_cast<std::size_t>(row_start_[static_cast<std::size_t>(i)])] + w_stay_;
      if (w_fair_ > 0) {
        const auto [begin, end] = topology_.ring(i);
        double laplacian = begin == end ? 0.0 : 1.0;
        for (const Index* k = begin; k != end; ++k)
          laplacian += inverse_valence_[static_cast<std::size_t>(*k)] * inverse_valence_[static_cast<std::size_t>(*k)];
        diagonal += w_fair_ * laplacian;
      }
      inverse[static_cast<std::size_t>(i)] = InverseFactor3f::scalar(1.0 / diagonal);
    });
    if (w_fair_ > 0) laplacian_.resize(b.size());
    ConjugateGradients cg(*this, std::move(inverse), b);
    const IterationResult result = cg.run(options.max_solver_iterations, kFitIterativeTolerance);
    report.solver_iterations += result.iterations;
    if (!result.converged) {
      // A safety net that no mesh measured needed (docs/benchmarks.md, "Fit solvers"); tested
      // by capping the iterations (FitSolvers.RoundsThatDoNotConvergeAreSolvedDirectly).
      ++report.solver_fallbacks;
      if (!direct_) direct_ = std::make_unique<DirectFitSystem>(F_, topology_, fixed_, options.fairness);
      laplacian_.resize(0);
      return direct_->solve(X, to_mesh, to_reference, options, report);
    }
    laplacian_.resize(0);
    Vertices X_out = X;
    const BlockVector& d = cg.solution();
    parallel_for_index(n_, [&](Index i) {
      if (is_free(i)) X_out.row(i) += block_at(d, i).transpose();
    });
    return X_out;
  }

  // BlockOperator: y = (D + w_f / n L^T L + w_p / n I) x over the free vertices, 0 at the fixed.
  double apply(const BlockVector& x, BlockVector& y) override {
    if (w_fair_ > 0) {
      // u = L x (x is 0 at the fixed vertices).
      parallel_for_index(n_, [&](Index k) {
        const auto [begin, end] = topology_.ring(k);
        Eigen::Vector3d u = Eigen::Vector3d::Zero();
        if (begin != end) {
          Eigen::Vector3d sum = Eigen::Vector3d::Zero();
          for (const Index* j = begin; j != end; ++j) sum += block_at(x, *j);
          u = block_at(x, k) - inverse_valence_[static_cast<std::size_t>(k)] * sum;
        }
        block_at(laplacian_, k) = u;
      });
    }
    return sum_over_vertices(n_, 0.0, [&](Index i) {
      Eigen::Vector3d yi = Eigen::Vector3d::Zero();
      if (!fixed_[static_cast<std::size_t>(i)]) {
        const auto begin = static_cast<std::size_t>(row_start_[static_cast<std::size_t>(i)]);
        const auto end = static_cast<std::size_t>(row_start_[static_cast<std::size_t>(i) + 1]);
        for (std::size_t at = begin; at < end; ++at) yi += values_[at] * block_at(x, columns_[at]);
        yi += w_stay_ * block_at(x, i);
        if (w_fair_ > 0) {
          // (L^T u)_i = L_ii u_i + sum over the ring of L_ki u_k (the ring is symmetric).
          const auto [ring_begin, ring_end] = topology_.ring(i);
          Eigen::Vector3d lt = Eigen::Vector3d::Zero();
          if (ring_begin != ring_end) lt = block_at(laplacian_, i);
          for (const Index* k = ring_begin; k != ring_end; ++k)
            lt -= inverse_valence_[static_cast<std::size_t>(*k)] * block_at(laplacian_, *k);
          yi += w_fair_ * lt;
        }
      }
      block_at(y, i) = yi;
      return block_at(x, i).dot(yi);
    });
  }

  double apply_updated(BlockVector& p, const PreconditionedResidual& z, double beta, BlockVector& y) override {
    parallel_for_index(n_, [&](Index i) { block_at(p, i) = z(i) + beta * block_at(p, i); });
    return apply(p, y);
  }

 private:
  // Pairs (k, l), k != l, in the order of face_slots_: (0,1) (0,2) (1,0) (1,2) (2,0) (2,1).
  static int pair_index(int k, int l) { return 2 * k + (l < k ? l : l - 1); }
  std::int32_t find_slot(Index row, Index column) const {
    const auto begin = static_cast<std::size_t>(row_start_[static_cast<std::size_t>(row)]);
    const auto end = static_cast<std::size_t>(row_start_[static_cast<std::size_t>(row) + 1]);
    for (std::size_t at = begin; at < end; ++at)
      if (columns_[at] == column) return static_cast<std::int32_t>(at);
    throw std::logic_error("fit: a face's corners are not in each other's rings");
  }

  const Faces& F_;
  const Topology& topology_;
  const std::vector<char>& fixed_;
  Index n_;
  std::vector<std::int64_t> row_start_;
  std::vector<Index> columns_;
  std::vector<std::int32_t> face_slots_;
  std::vector<double> inverse_valence_;
  std::vector<double> values_;
  BlockVector laplacian_;  // L x during an iteration
  double w_fair_ = 0, w_stay_ = 0;
  std::unique_ptr<DirectFitSystem> direct_;  // the fallback, made when first needed
};

}  // namespace

std::unique_ptr<FitSystem> make_fit_system(const Faces& F, const Topology& topology, const std::vector<char>& fixed,
                                           const FitOptions& options) {
  if (options.solver == FitSolver::Iterative) return std::make_unique<IterativeFitSystem>(F, topology, fixed, options);
  return std::make_unique<DirectFitSystem>(F, topology, fixed, options.fairness);
}

}  // namespace vertexflow
