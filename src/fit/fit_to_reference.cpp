// Fitting to a reference surface (fit.h): Hoppe et al.'s distance energy over the vertex
// positions, with foot points iterated and the flow's guard after every solve.
#include "vertexflow/fit.h"

#include "../flow/guard.h"
#include "vertexflow/distance.h"
#include "vertexflow/features.h"
#include "vertexflow/timing.h"
#include "vertexflow/topology.h"

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <algorithm>
#include <chrono>
#include <cmath>
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

// The data rows of one round: the reference's samples at their foot points on the mesh X, and
// the mesh's vertices and face centroids at their closest points on the reference. Returns the
// mean squared distance of each direction.
std::pair<double, double> data_rows(const Vertices& X, const Faces& F, const Vertices& samples,
                                    const DistanceQuery& reference, std::vector<DataRow>& to_mesh,
                                    std::vector<DataRow>& to_reference) {
  const DistanceQuery mesh(X, F);
  const std::vector<ClosestPoint> feet = mesh.closest_points(samples);
  to_mesh.resize(feet.size());
  double sum_to_mesh = 0;
  for (std::size_t j = 0; j < feet.size(); ++j) {
    to_mesh[j] = {F.row(feet[j].face).transpose(), feet[j].barycentric, samples.row(static_cast<Index>(j)).transpose()};
    sum_to_mesh += feet[j].squared_distance;
  }
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
        s < n ? DataRow{{static_cast<int>(s), static_cast<int>(s), static_cast<int>(s)}, {1.0, 0.0, 0.0}, c.point}
              : DataRow{F.row(s - n).transpose(), Eigen::Vector3d::Constant(1.0 / 3.0), c.point};
    sum_to_reference += c.squared_distance;
  }
  return {sum_to_mesh / static_cast<double>(feet.size()), sum_to_reference / static_cast<double>(n + m)};
}

// An n x n system with three right-hand sides, factored once per round: Eigen's simplicial
// LDL^T is exact, deterministic and fast enough at the sizes fitting runs on (the flow's CHOLMOD
// wrapper is built for its 3n x 3n block system). Every round's matrix has the same pattern
// (L^T L and every face's corner pairs, stored even where a round puts no sample), so the
// ordering and symbolic analysis of the first round serve all.
struct RoundSolver {
  Eigen::SimplicialLDLT<SparseMatrix> ldlt;
  bool analysed = false;
};

// Minimises the energy of fit.h for fixed data rows; fixed vertices keep their rows of X.
Vertices solve_round(const Vertices& X, const Faces& F, const std::vector<DataRow>& to_mesh,
                     const std::vector<DataRow>& to_reference, const SparseMatrix& laplacian_normal,
                     const std::vector<char>& fixed, const FitOptions& options, RoundSolver& solver) {
  const Index n = X.rows();
  // Unknowns: the free vertices, in index order.
  std::vector<Index> unknown(static_cast<std::size_t>(n), -1);
  Index free_count = 0;
  for (Index i = 0; i < n; ++i) {
    if (!fixed[static_cast<std::size_t>(i)]) unknown[static_cast<std::size_t>(i)] = free_count++;
  }
  Vertices X_out = X;
  if (free_count == 0) return X_out;
  std::vector<Triplet> entries;
  entries.reserve(9 * (to_mesh.size() + to_reference.size()) + static_cast<std::size_t>(laplacian_normal.nonZeros()));
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(free_count, 3);
  // Adds w |sum_k b_k x_{i_k} - t|^2: the free corners go to the matrix, the fixed ones to the
  // right-hand side.
  auto add_row = [&](const Eigen::Vector3i& corners, const Eigen::Vector3d& b, const Eigen::Vector3d& target,
                     double w) {
    Eigen::Vector3d t = target;
    for (int k = 0; k < 3; ++k) {
      if (unknown[static_cast<std::size_t>(corners[k])] < 0 && b[k] != 0) t -= b[k] * X.row(corners[k]).transpose();
    }
    for (int k = 0; k < 3; ++k) {
      const Index r = unknown[static_cast<std::size_t>(corners[k])];
      if (r < 0 || b[k] == 0) continue;
      rhs.row(r) += w * b[k] * t.transpose();
      for (int l = 0; l < 3; ++l) {
        const Index c = unknown[static_cast<std::size_t>(corners[l])];
        if (c >= 0 && b[l] != 0) entries.emplace_back(r, c, w * b[k] * b[l]);
      }
    }
  };
  const double w_mesh = 1.0 / static_cast<double>(to_mesh.size());
  for (const DataRow& row : to_mesh) add_row(row.corners, row.weights, row.target, w_mesh);
  const double w_reference = options.mesh_to_reference_weight / static_cast<double>(to_reference.size());
  for (const DataRow& row : to_reference) add_row(row.corners, row.weights, row.target, w_reference);
  // w_f / n |L (x - x_k)|^2: matrix (w_f / n) L^T L, right-hand side (w_f / n) L^T L x_k, whose
  // fixed columns cancel against the same columns moved to the right: only free-free entries
  // and the free rows of L^T L x_k over the free vertices remain.
  const double w_fair = options.fairness / static_cast<double>(n);
  for (Index col = 0; col < laplacian_normal.outerSize(); ++col) {
    const Index c = unknown[static_cast<std::size_t>(col)];
    if (c < 0) continue;
    for (SparseMatrix::InnerIterator it(laplacian_normal, col); it; ++it) {
      const Index r = unknown[static_cast<std::size_t>(it.row())];
      if (r < 0) continue;
      entries.emplace_back(r, c, w_fair * it.value());
      rhs.row(r) += w_fair * it.value() * X.row(col);
    }
  }
  for (Index f = 0; f < F.rows(); ++f) {  // the fixed pattern (RoundSolver)
    for (int k = 0; k < 3; ++k) {
      for (int l = 0; l < 3; ++l) {
        const Index r = unknown[static_cast<std::size_t>(F(f, k))], c = unknown[static_cast<std::size_t>(F(f, l))];
        if (r >= 0 && c >= 0) entries.emplace_back(r, c, 0.0);
      }
    }
  }
  // w_p / n |x - x_k|^2.
  const double w_stay = options.proximity / static_cast<double>(n);
  for (Index i = 0; i < n; ++i) {
    const Index r = unknown[static_cast<std::size_t>(i)];
    if (r < 0) continue;
    entries.emplace_back(r, r, w_stay);
    rhs.row(r) += w_stay * X.row(i);
  }
  SparseMatrix A(free_count, free_count);
  A.setFromTriplets(entries.begin(), entries.end());
  if (!solver.analysed) {
    solver.ldlt.analyzePattern(A);
    solver.analysed = true;
  }
  solver.ldlt.factorize(A);
  if (solver.ldlt.info() != Eigen::Success)
    throw std::runtime_error("fit to reference: the system is not positive definite");
  const Eigen::MatrixXd x = solver.ldlt.solve(rhs);
  for (Index i = 0; i < n; ++i) {
    const Index r = unknown[static_cast<std::size_t>(i)];
    if (r >= 0) X_out.row(i) = x.row(r);
  }
  return X_out;
}

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

  auto start = Clock::now();
  const DistanceQuery reference(VR, FR);
  SamplingOptions sampling;
  sampling.samples = static_cast<Index>(std::ceil(options.samples_per_vertex * static_cast<double>(n)));
  sampling.seed = options.seed;
  sampling.vertices = false;
  sampling.edge_midpoints = false;
  const Vertices samples = sample_surface(VR, FR, sampling).points;
  report.reference_samples = samples.rows();
  report.seconds_tree += seconds_since(start);

  const SparseMatrix L = uniform_laplacian(topology, n);
  const SparseMatrix laplacian_normal = SparseMatrix(L.transpose()) * L;
  const GuardCriteria criteria = guard_criteria(V, F, options.min_quality, options.sliver_floor);
  FlowOptions guard_options;
  guard_options.project_to_input = false;  // the fit leaves the input on purpose
  const SurfaceFeatures no_features = detect_features(V, F, topology, 180.0);
  std::vector<char> shortened(static_cast<std::size_t>(n), 0);
  FlowReport guard_report;

  RoundSolver solver;
  Vertices X = V, last = V;
  std::vector<DataRow> to_mesh, to_reference;
  double previous = 0;
  for (int round = 0;; ++round) {
    start = Clock::now();
    const auto [to_mesh_ms, to_reference_ms] = data_rows(X, F, samples, reference, to_mesh, to_reference);
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
    Vertices Y = solve_round(X, F, to_mesh, to_reference, laplacian_normal, fixed, options, solver);
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
