// The fit's linear system and rounds (fit_rounds.h).
#include "fit_rounds.h"

#include "../guard/guard.h"
#include "numerics/sparse_cholesky.h"
#include "vertexflow/timing.h"

#include <Eigen/SparseCore>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>

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

}  // namespace

void validate_fit(const Vertices& V, const Faces& F, const FitOptions& o, const std::string& context) {
  if (V.rows() == 0 || F.rows() == 0) throw std::invalid_argument(context + ": the mesh is empty");
  if (!V.allFinite()) throw std::invalid_argument(context + ": a coordinate is not finite");
  validate_fit_options(o, V.rows(), context.c_str());
}

void validate_fit_options(const FitOptions& o, Index num_vertices, const char* what) {
  auto require = [what](bool ok, const std::string& problem) {
    if (!ok) throw std::invalid_argument(std::string(what) + ": " + problem);
  };
  require(std::isfinite(o.samples_per_vertex) && o.samples_per_vertex > 0, "samples_per_vertex must be > 0");
  require(std::isfinite(o.mesh_to_reference_weight) && o.mesh_to_reference_weight >= 0,
          "mesh_to_reference_weight must be a finite number >= 0");
  require(std::isfinite(o.fairness) && o.fairness >= 0, "fairness must be a finite number >= 0");
  require(std::isfinite(o.proximity) && o.proximity > 0, "proximity must be a finite number > 0");
  require(o.max_rounds >= 1, "max_rounds must be at least 1");
  require(std::isfinite(o.tolerance) && o.tolerance >= 0, "tolerance must be a finite number >= 0");
  validate_guard_options(o.guard, what);
  validate_vertex_constraints(o.constraints, num_vertices, what);
}

// The n x n system of one round, with three right-hand sides (x, y, z), on a pattern fixed
// for all rounds: every round's matrix is L^T L, every face's corner pairs (stored even where
// a round puts no sample) and the diagonal, over the free vertices. Every data row lies in one
// face (or is one vertex), so a round adds its rows into precomputed slots of the values
// array, and CHOLMOD (sparse_cholesky.h: supernodal, exact, deterministic) reuses its ordering
// and symbolic analysis. Measured on bench_fit (10k vertices): assembling triplets and
// Eigen's simplicial LDL^T took 186 ms per round; this takes about a fifth of that.
class FitSystem {
 public:
  FitSystem(const Faces& F, const SparseMatrix& laplacian_normal, const std::vector<char>& fixed) {
    const auto n = static_cast<Index>(fixed.size());
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

  /// Minimises the energy of fit.h for fixed data rows; fixed vertices keep their rows of X.
  Vertices solve(const Vertices& X, const std::vector<DataRow>& to_mesh, const std::vector<DataRow>& to_reference,
                 const FitOptions& options) {
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
    auto add_row = [&](const DataRow& row, double direction_weight) {
      const double w = direction_weight * row.weight;
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
    };
    auto total_weight = [](const std::vector<DataRow>& rows) {
      double sum = 0;
      for (const DataRow& row : rows) sum += row.weight;
      return sum;
    };
    if (!to_mesh.empty()) {
      const double w_mesh = 1.0 / total_weight(to_mesh);
      for (const DataRow& row : to_mesh) add_row(row, w_mesh);
    }
    if (!to_reference.empty()) {
      const double w_reference = options.mesh_to_reference_weight / total_weight(to_reference);
      for (const DataRow& row : to_reference) add_row(row, w_reference);
    }
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

FitRounds::FitRounds(const Vertices& V, const Faces& F, const FitOptions& options)
    : FitRounds(V, F, build_topology(F, V.rows()), options) {}

FitRounds::FitRounds(const Vertices& V, const Faces& F, Topology topology, const FitOptions& options)
    : V_(V), F_(F), options_(options), topology_(std::move(topology)) {
  const Index n = V.rows();
  fixed_.assign(static_cast<std::size_t>(n), 0);
  for (Index i = 0; i < n; ++i) {
    const auto v = static_cast<std::size_t>(i);
    // Vertices without faces have no data and no ring: nothing decides where they go.
    fixed_[v] = (options.constraints.fix_boundary && topology_.is_boundary_vertex[v]) ||
                topology_.face_offsets[v] == topology_.face_offsets[v + 1];
  }
  for (const Index p : options.constraints.pinned) fixed_[static_cast<std::size_t>(p)] = 1;
  // Without fairness the pattern is the faces' alone, whose factor fills in far less than with
  // the anchored Laplacian's two-rings.
  const SparseMatrix L = options.fairness > 0 ? uniform_laplacian(topology_, n) : SparseMatrix(n, n);
  system_ = std::make_unique<FitSystem>(F, SparseMatrix(SparseMatrix(L.transpose()) * L), fixed_);
  criteria_ = std::make_unique<GuardCriteria>(guard_criteria(V, F, options.guard));
  shortened_.assign(static_cast<std::size_t>(n), 0);
}

FitRounds::~FitRounds() = default;

Vertices FitRounds::step(const Vertices& X, const std::vector<DataRow>& to_mesh,
                         const std::vector<DataRow>& to_reference, FitReport& report) {
  auto start = Clock::now();
  Vertices Y = system_->solve(X, to_mesh, to_reference, options_);
  report.seconds_solve += seconds_since(start);
  start = Clock::now();
  // No reprojection: the fit leaves the input on purpose.
  const GuardCounts counts = guard(Y, X, *criteria_, fixed_, topology_, options_.guard, {}, shortened_);
  guard_counts_.flipped_before_guard += counts.flipped_before_guard;
  guard_counts_.low_quality_before_guard += counts.low_quality_before_guard;
  report.seconds_guard += seconds_since(start);
  return Y;
}

Vertices FitRounds::finish(Vertices X, FitReport& report) const {
  report.flipped_before_guard = guard_counts_.flipped_before_guard;
  report.low_quality_before_guard = guard_counts_.low_quality_before_guard;
  report.limited_vertices = static_cast<Index>(std::count(shortened_.begin(), shortened_.end(), 1));
  for (Index i = 0; i < X.rows(); ++i) {
    if (fixed_[static_cast<std::size_t>(i)]) X.row(i) = V_.row(i);
  }
  return X;
}

}  // namespace vertexflow
