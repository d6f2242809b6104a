// Fitting to a reference surface (fit.h): Hoppe et al.'s distance energy over the vertex
// positions, with foot points iterated and the flow's guard after every solve.
#include "vertexflow/fit.h"

#include "../flow/guard.h"
#include "numerics/sparse_cholesky.h"
#include "vertexflow/distance.h"
#include "vertexflow/features.h"
#include "vertexflow/timing.h"
#include "vertexflow/topology.h"

#include <tbb/parallel_invoke.h>
#include <Eigen/SparseCore>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>

namespace vertexflow {
namespace {

using SparseMatrix = Eigen::SparseMatrix<double>;
using Triplet = Eigen::Triplet<double>;

void validate(const Vertices& V, const Faces& F, const Vertices& VR, const Faces& FR, const FitOptions& o) {
  auto require = [](bool ok, const std::string& what) {
    if (!ok) throw std::invalid_argument("fit to reference: " + what);
  };
  require(V.rows() > 0 && F.rows() > 0, "the mesh is empty");
  require(VR.rows() > 0 && FR.rows() > 0, "the reference is empty");
  require(V.allFinite() && VR.allFinite(), "a coordinate is not finite");
  require(std::isfinite(o.samples_per_vertex) && o.samples_per_vertex > 0, "samples_per_vertex must be > 0");
  require(std::isfinite(o.mesh_to_reference_weight) && o.mesh_to_reference_weight >= 0,
          "mesh_to_reference_weight must be a finite number >= 0");
  require(std::isfinite(o.fairness) && o.fairness > 0, "fairness must be a finite number > 0");
  require(std::isfinite(o.proximity) && o.proximity > 0, "proximity must be a finite number > 0");
  require(o.max_rounds >= 1, "max_rounds must be at least 1");
  require(std::isfinite(o.tolerance) && o.tolerance >= 0, "tolerance must be a finite number >= 0");
  require(o.min_quality >= 0 && o.min_quality <= 1, "min_quality must be in [0, 1]");
  require(o.sliver_floor >= 0 && o.sliver_floor <= 1, "sliver_floor must be in [0, 1]");
  for (const Index p : o.pinned)
    require(p >= 0 && p < V.rows(), "pinned vertex " + std::to_string(p) + " is out of range");
}

// A point of the mesh as a combination of (up to) three vertices, and the point of the other
// surface it should reach.
struct DataRow {
  Index face = -1;  ///< the face whose corners these are; -1 for a vertex (corners all equal)
  Eigen::Vector3i corners;
  Eigen::Vector3d weights;
  Eigen::Vector3d target;
};

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

// The data rows of one round, first direction: the reference's samples at their foot points on
// the mesh X. Returns their mean squared distance.
double rows_to_mesh(const Vertices& X, const Faces& F, const Vertices& samples, std::vector<DataRow>& to_mesh) {
  const DistanceQuery mesh(X, F);
  const std::vector<ClosestPoint> feet = mesh.closest_points(samples);
  to_mesh.resize(feet.size());
  double sum_to_mesh = 0;
  for (std::size_t j = 0; j < feet.size(); ++j) {
    to_mesh[j] = {feet[j].face, F.row(feet[j].face).transpose(), feet[j].barycentric,
                  samples.row(static_cast<Index>(j)).transpose()};
    sum_to_mesh += feet[j].squared_distance;
  }
  return sum_to_mesh / static_cast<double>(feet.size());
}

// Second direction: the mesh's vertices and face centroids at their closest points on the
// reference. Returns their mean squared distance.
double rows_to_reference(const Vertices& X, const Faces& F, const DistanceQuery& reference,
                         std::vector<DataRow>& to_reference) {
  const Index n = X.rows(), m = F.rows();
  Vertices points(n + m, 3);
  points.topRows(n) = X;
  for (Index f = 0; f < m; ++f) points.row(n + f) = (X.row(F(f, 0)) + X.row(F(f, 1)) + X.row(F(f, 2))) / 3.0;
  const std::vector<ClosestPoint> closest = reference.closest_points(points);
  to_reference.resize(closest.size());
  double sum_to_reference = 0;
  for (Index s = 0; s < n + m; ++s) {
    const ClosestPoint& c = closest[static_cast<std::size_t>(s)];
    to_reference[static_cast<std::size_t>(s)] =
        s < n ? DataRow{-1, {static_cast<int>(s), static_cast<int>(s), static_cast<int>(s)}, {1.0, 0.0, 0.0}, c.point}
              : DataRow{s - n, F.row(s - n).transpose(), Eigen::Vector3d::Constant(1.0 / 3.0), c.point};
    sum_to_reference += c.squared_distance;
  }
  return sum_to_reference / static_cast<double>(n + m);
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
    auto add_row = [&](const DataRow& row, double w) {
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
    const double w_mesh = 1.0 / static_cast<double>(to_mesh.size());
    for (const DataRow& row : to_mesh) add_row(row, w_mesh);
    const double w_reference = options.mesh_to_reference_weight / static_cast<double>(to_reference.size());
    for (const DataRow& row : to_reference) add_row(row, w_reference);
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

}  // namespace

FitResult fit_to_reference(const Vertices& V, const Faces& F, const Vertices& VR, const Faces& FR,
                           const FitOptions& options) {
  validate(V, F, VR, FR, options);
  FitResult result;
  FitReport& report = result.report;
  const Index n = V.rows();
  const Topology topology = build_topology(F, n);
  std::vector<char> fixed(static_cast<std::size_t>(n), 0);
  for (Index i = 0; i < n; ++i) {
    const auto v = static_cast<std::size_t>(i);
    // Vertices without faces have no data and no ring: nothing decides where they go.
    fixed[v] = (options.fix_boundary && topology.is_boundary_vertex[v]) ||
               topology.face_offsets[v] == topology.face_offsets[v + 1];
  }
  for (const Index p : options.pinned) fixed[static_cast<std::size_t>(p)] = 1;

  const SparseMatrix L = uniform_laplacian(topology, n);
  const SparseMatrix laplacian_normal = SparseMatrix(L.transpose()) * L;
  const GuardCriteria criteria = guard_criteria(V, F, options.min_quality, options.sliver_floor);
  FlowOptions guard_options;
  guard_options.project_to_input = false;  // the fit leaves the input on purpose
  const SurfaceFeatures no_features = detect_features(V, F, topology, 180.0);
  std::vector<char> shortened(static_cast<std::size_t>(n), 0);
  FlowReport guard_report;

  // The reference's tree (CGAL builds it on one thread per half, distance.cpp) alongside its
  // samples and the system's ordering and analysis.
  auto start = Clock::now();
  std::optional<DistanceQuery> reference;
  std::optional<FitSystem> system;
  Vertices samples;
  std::vector<DataRow> to_mesh, to_reference;
  tbb::parallel_invoke([&] { reference.emplace(VR, FR); },
                       [&] {
                         SamplingOptions sampling;
                         sampling.samples =
                             static_cast<Index>(std::ceil(options.samples_per_vertex * static_cast<double>(n)));
                         sampling.seed = options.seed;
                         sampling.vertices = false;
                         sampling.edge_midpoints = false;
                         samples = sample_surface(VR, FR, sampling).points;
                         system.emplace(F, laplacian_normal, fixed);
                       });
  report.reference_samples = samples.rows();
  report.seconds_tree += seconds_since(start);

  Vertices X = V, last = V;
  double previous = 0;
  for (int round = 0;; ++round) {
    start = Clock::now();
    const double to_mesh_ms = rows_to_mesh(X, F, samples, to_mesh);
    const double to_reference_ms = rows_to_reference(X, F, *reference, to_reference);
    report.seconds_queries += seconds_since(start);
    const double energy = 0.5 * (to_mesh_ms + to_reference_ms);
    report.rms_distance.push_back(std::sqrt(energy));
    if (round > 0 && !(previous - energy > options.tolerance * previous)) {
      report.converged = true;
      if (energy > previous) {  // the round made it worse (the guard held it back): undo it
        X = std::move(last);
        report.rms_distance.pop_back();
        --report.rounds;
      }
      break;
    }
    if (round == options.max_rounds) break;
    previous = energy;
    start = Clock::now();
    Vertices Y = system->solve(X, to_mesh, to_reference, options);
    report.seconds_solve += seconds_since(start);
    start = Clock::now();
    guard(Y, X, V, criteria, fixed, topology, no_features, guard_options, shortened, guard_report);
    report.seconds_guard += seconds_since(start);
    last = std::move(X);
    X = std::move(Y);
    report.rounds = round + 1;
  }
  report.flipped_before_guard = guard_report.flipped_before_guard;
  report.low_quality_before_guard = guard_report.low_quality_before_guard;
  report.limited_vertices = static_cast<Index>(std::count(shortened.begin(), shortened.end(), 1));
  // Fixed vertices are returned bit for bit.
  for (Index i = 0; i < n; ++i) {
    if (fixed[static_cast<std::size_t>(i)]) X.row(i) = V.row(i);
  }
  result.V = std::move(X);
  return result;
}

}  // namespace vertexflow
