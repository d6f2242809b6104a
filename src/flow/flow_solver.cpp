// Solves the flow's normal equations H d = b (flow_terms.h) by one of three methods, and
// chooses among them. The pieces: H's factors (flow_terms.h), H applied matrix-free and its
// Galerkin projection (flow_operator.h), H assembled (normal_matrix.h); the methods are in
// src/numerics/ (conjugate_gradients.h, aggregation_coarse_space.h, multigrid.h,
// sparse_cholesky.h).
//
// - Direct: H's 3x3 blocks (two-ring pattern) assembled from that sum; a fill-reducing
//   ordering of the vertex graph (CHOLMOD: AMD, or METIS when AMD fills badly) expanded to the
//   three coordinates, which gives the same fill as ordering the 3n graph at a ninth of the
//   cost; CHOLMOD's supernodal Cholesky with one BLAS thread. The ordering and the symbolic
//   factorisation depend only on the connectivity and are kept between solves.
// - Iterative: conjugate gradients on the matrix-free H, started from the input (d = 0),
//   preconditioned by the inverses of H's 3x3 diagonal blocks, which capture each vertex's
//   anisotropy (stiff along the normal, soft in the tangent plane) exactly.
// - Multilevel: the same iteration with a coarse space added to the preconditioner
//   (aggregation_coarse_space.h, multigrid.h): smoothed aggregates of one-rings whose Galerkin
//   matrix is coarsened again, with smoothed prolongators where a large region is planar and
//   tentative ones elsewhere (kPlanarRegionForSmoothing). It is for the smooth tangential modes
//   of large flat regions, and for long runs on large curved meshes.
//
// Why these two and how the choice is made (measured on this project's meshes, docs/benchmarks.md):
// the coupled factorisation costs about n^1.5 (3.1e9 flops at 9k vertices, 1.8e10 at 43k, an
// estimated 2e12 and 16 GB at 1M), the iteration costs about n, and the iteration count stays
// between 80 and 300 on smooth meshes of any size at the tolerance 1e-7 (bunny 9k: 80,
// amo 90k: 291; 98 and 416 at 1e-9) but reaches 900-1,100 where large flat regions leave
// tangential motion to the bi-Laplacian of F_smo and the tiny pull (fandisk). Preconditioners
// built on decoupled n x n factorisations (x, y, z, or per-vertex frames) and their two-level
// combinations with Gauss-Seidel cost a factorisation each and still took 50-200 iterations,
// so they lost to the two above everywhere; the aggregation coarse space needs no
// factorisation of the fine problem and cuts fandisk from 930 to 114 iterations.
// The automatic rule is therefore competitive: below kDirectBelow free vertices factor
// directly; otherwise iterate (with the multilevel preconditioner where a large flat region
// predicts slow modes, kFlatRegionForMultilevel), and if the iteration has not converged after about the number
// of iterations that the factorisation would take to run (kBudgetPerSqrtVertex * sqrt(free
// vertices), calibrated on this machine) fall back to the factorisation when its predicted
// memory fits, so the total is at most about twice the better of the two. It depends only on
// counts, so the output bytes do not depend on timings or thread counts.
#include "flow_solver.h"

#include "flow_operator.h"
#include "flow_terms.h"
#include "normal_matrix.h"
#include "numerics/aggregation_coarse_space.h"
#include "numerics/conjugate_gradients.h"
#include "numerics/parallel.h"
#include "numerics/sparse_cholesky.h"
#include "numerics/vertex_ordering.h"

#include "vertexflow/progress.h"
#include "vertexflow/timing.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <optional>
#include <stdexcept>

namespace vertexflow {
namespace {

// Free vertices at or below this count are factored directly: a few milliseconds, exact, and
// no iteration count to depend on (sphere_low, 589 vertices: 20 ms CPU direct, 1 ms iterating).
constexpr Index kDirectBelow = 1000;
// Iterations allowed before the fallback to the factorisation: the factorisation's time over
// one iteration's time, both measured on bunny_uniform, armadillo-43k and amo (time ~ 4.5e-7
// n^1.5 s against ~2.5e-8 n s on 2 cores, so the ratio is about 18 sqrt(n)).
constexpr double kBudgetPerSqrtVertex = 18.0;
// LinearSolver::Automatic takes the multilevel preconditioner when a connected region of at
// least kFlatRegionForMultilevel free vertices has |k1| + |k2| < kFlatCurvaturePerEdge (per mean edge
// length): there F_em vanishes and block-Jacobi's iteration count grows like the region's
// diameter squared. Measured (largest such region; block-Jacobi against multilevel
// iterations): fandisk 1,257 vertices, 930 against 114; amo 4,825, 291 against 97; every other
// data mesh at most 105 vertices. Starting multilevel at once saves the probe below.
constexpr double kFlatCurvaturePerEdge = 0.01;
constexpr Index kFlatRegionForMultilevel = 500;
// The multilevel path's hierarchy (AdditiveMultilevel, on the coarse problem) smooths its
// prolongators only where a connected region of at least kPlanarRegionForSmoothing free
// vertices is planar at the mesh's own scale: |k1| + |k2| < kPlanarCurvature / sqrt(n) per
// mean edge length, n the vertex count (a sphere of n vertices has 7.7 / sqrt(n); sqrt(n) edge
// lengths measure the surface however fine the mesh, and unlike a bounding box do not turn with
// it). There the tangential stiffness is F_smo's bi-Laplacian, which the tentative prolongators
// approximate badly; on curved surfaces the tentative ones took as few or fewer iterations and
// a third less set-up. Measured (largest planar region; `--solver multilevel` iterations
// smoothed against tentative, docs/benchmarks.md): fandisk split to 932k vertices 214,316, 155
// / 344 (measured in an earlier session); chamfer-cube split to 141k 5,929, 114 / 255; fandisk 1,257, 54 / 68; against
// amo 301, 48 / 37; the 10M armadillo (each edge split in three) 144, 72 / 64 (set-up 15.7 / 11.6 s); rocker-arm split
// to 362k 18, 56 / 40. The test of kFlatCurvaturePerEdge, relative to the edge length, does not separate them: a finer
// mesh looks flatter, and the 10M armadillo's largest region under it has 1,556 vertices.
constexpr double kPlanarCurvature = 0.1;
constexpr Index kPlanarRegionForSmoothing = 600;  // between 301 and 1,257, a factor of two from each
// The iterations' products keep the operator's per-vertex caches in float (flow_operator.h: 48
// bytes per vertex less at the solve's peak) where they stop at a relative residual of at least
// this, 20 times those products' rounding (about 5e-8); tighter tolerances get exact products,
// as b, the direct path and the reported residual always do.
constexpr double kFloatCachesFromTolerance = 1e-6;
// Otherwise block-Jacobi runs kProbeIterations, and if the Lanczos estimate of its total
// (ConjugateGradients::predicted_iterations, a lower bound) is above kSwitchAbovePredicted the
// iteration continues with the multilevel preconditioner. The set-up costs about 30-50
// block-Jacobi iterations, and the multilevel count is 40-70% of block-Jacobi's, so it pays from
// about 120 remaining iterations. Measured after 30 iterations (estimate; actual count):
// bunny_uniform 67; 79, horse-48k 89; 93, rocker-arm 91; 90, armadillo-43k 95; 129 stay;
// max-planck-5k 111; 146, fertility 113; 140, spot 121; 222, camelhead 149; 568 switch.
// The estimates above are at the tolerance they were calibrated at, kSwitchPredictedAt; the
// rule predicts at it whatever the solve's tolerance, so the path depends on the mesh and the
// weights only (the first kProbeIterations iterates do not depend on the tolerance).
constexpr int kProbeIterations = 30;
constexpr double kSwitchAbovePredicted = 105;
constexpr double kSwitchPredictedAt = 1e-7;
// Without a fallback (the factorisation would not fit) the iteration stops at this many
// times the budget.
constexpr int kIterationCapFactor = 10;
// The fallback is taken only when the predicted factor (9 x the vertex graph's fill) fits.
constexpr double kMaxFactorBytes = 2.0 * 1024 * 1024 * 1024;

// The iterations run in chunks of this many between progress reports: at 1M vertices about
// half a second, a few dozen reports per solve. Resuming is exact (conjugate_gradients.h keeps
// its state), so the iterates are those of one uninterrupted run.
constexpr int kIterationsPerReport = 10;
// The solve's part before the iterations (assembly, preconditioner): a tenth, for the progress.
constexpr double kSetUpShare = 0.1;

// At most max_iterations of cg, reporting `phase` between chunks at the fraction of the way from
// |r| = |b| to |r| = tolerance |b| on a log scale (progress.h), never below `done` (the most
// reported so far: the residual of conjugate gradients is not monotone). Returns what one
// cg.run would.
IterationResult run_reporting(ConjugateGradients& cg, int max_iterations, double tolerance, const std::string& phase,
                              double& done) {
  IterationResult total;
  do {  // at least once: a run of 0 iterations still says whether the iterate has converged
    const int chunk = std::clamp(max_iterations - total.iterations, 0, kIterationsPerReport);
    const IterationResult part = cg.run(chunk, tolerance);
    total.iterations += part.iterations;
    const double residual = cg.relative_residual();
    done = std::max(done, residual > 0 ? std::clamp(std::log(residual) / std::log(tolerance), 0.0, 1.0) : 1.0);
    report_progress(phase, kSetUpShare + (1 - kSetUpShare) * done, 1);
    if (part.converged) {
      total.converged = true;
      break;
    }
    if (part.iterations < chunk) break;  // stopped at a non-positive curvature, as one run would
  } while (total.iterations < max_iterations);
  return total;
}

// Whether a connected region of at least `size` free vertices has |k1| + |k2| < flat (per mean
// edge length). The search stops at the first such region: on a scan split into planar facets
// (the 10M armadillo) the flat vertices are half the mesh, and visiting them all took 0.15 s.
bool has_flat_region(const FlowTerms& t, double flat, Index size) {
  const auto n = static_cast<std::size_t>(t.n);
  std::vector<char> open(n);  // flat and not yet visited
  parallel_for_index(t.n, [&](Index i) {
    const auto v = static_cast<std::size_t>(i);
    open[v] = !t.fixed[v] && t.K[v].trace() < flat;  // trace(K) = |k1| + |k2|
  });
  std::vector<Index> queue;
  for (Index seed = 0; seed < t.n; ++seed) {
    if (!open[static_cast<std::size_t>(seed)]) continue;
    open[static_cast<std::size_t>(seed)] = 0;
    queue.assign(1, seed);
    for (std::size_t head = 0; head < queue.size(); ++head) {
      if (static_cast<Index>(queue.size()) >= size) return true;
      const auto [begin, end] = t.one_ring(queue[head]);
      for (const Index* j = begin; j != end; ++j)
        if (open[static_cast<std::size_t>(*j)]) {
          open[static_cast<std::size_t>(*j)] = 0;
          queue.push_back(*j);
        }
    }
    if (static_cast<Index>(queue.size()) >= size) return true;
  }
  return false;
}

// The multilevel correction, or null if its coarsest matrix lost definiteness to rounding
// (degenerate input): block-Jacobi alone still converges, only more slowly.
std::unique_ptr<CoarseSpaceCorrection> make_multilevel(const FlowTerms& terms) {
  try {
    const AdditiveMultilevel::Prolongators prolongators = multilevel_prolongators(terms);
    auto space = std::make_shared<const AggregationCoarseSpace>(terms.ring_start, terms.ring, terms.fixed);
    return std::make_unique<CoarseSpaceCorrection>(space, galerkin_upper(terms, *space), prolongators);
  } catch (const std::runtime_error&) {
    return nullptr;
  }
}

}  // namespace

std::vector<InverseFactor3f> block_jacobi(const FlowTerms& t) {
  std::vector<InverseFactor3f> inverse(static_cast<std::size_t>(t.n));
  parallel_for_index(t.n, [&](Index u) {
    const auto v = static_cast<std::size_t>(u);
    if (!t.fixed[v]) inverse[v] = InverseFactor3f::of_inverse(diagonal_block(t, u));
  });
  return inverse;
}

AdditiveMultilevel::Prolongators multilevel_prolongators(const FlowTerms& terms) {
  const double planar = kPlanarCurvature / std::sqrt(static_cast<double>(std::max<Index>(terms.n, 1)));
  return has_flat_region(terms, planar, kPlanarRegionForSmoothing) ? AdditiveMultilevel::Prolongators::Smoothed
                                                                   : AdditiveMultilevel::Prolongators::Tentative;
}

struct FlowSystemSolver::Impl {
  const Topology& topology;
  std::vector<char> fixed;
  LinearSolver kind;
  double tolerance;
  // Local numbering (FlowTerms), chosen at the first solve and kept: the pattern and the
  // ordering below are in it.
  std::vector<Index> order;
  std::optional<NormalMatrixPattern> pattern;
  std::optional<SparseCholesky::Ordering> ordering;  // of the free vertex graph
  SparseCholesky cholesky;
  std::string progress_phase = "solve";

  Impl(const Topology& t, std::vector<char> f, LinearSolver k, double tol)
      : topology(t), fixed(std::move(f)), kind(k), tolerance(tol) {}

  [[nodiscard]] Index num_free() const { return static_cast<Index>(std::count(fixed.begin(), fixed.end(), 0)); }

  void number_vertices(const Vertices& P) {
    if (order.empty() && P.rows() > 0) order = breadth_first_order(topology, space_filling_order(P));
  }
  const NormalMatrixPattern& pattern_of(const FlowTerms& terms) {
    if (!pattern) pattern = normal_matrix_pattern(terms);
    return *pattern;
  }
  // A fill-reducing ordering of the free vertex graph, and its predicted fill.
  const SparseCholesky::Ordering& vertex_ordering(const FlowTerms& terms) {
    if (!ordering) {
      const NormalMatrixPattern& p = pattern_of(terms);
      try {
        ordering = cholesky.order(p.row_start, p.row_columns);
      } catch (const std::runtime_error& e) {
        throw std::runtime_error(std::string("vertex flow: ") + e.what());
      }
    }
    return *ordering;
  }
  BlockVector factor_and_solve(const FlowTerms& terms, const BlockVector& b, FlowReport& report);
};

BlockVector FlowSystemSolver::Impl::factor_and_solve(const FlowTerms& terms, const BlockVector& b, FlowReport& report) {
  const Index m = num_free();
  auto start = Clock::now();
  const SparseCholesky::Ordering& vertices = vertex_ordering(terms);
  const NormalMatrixPattern& p = pattern_of(terms);
  SparseCholesky::UpperMatrix A = assemble_normal_matrix(terms, p, cholesky);
  report.seconds_assembly += seconds_since(start);

  start = Clock::now();
  // The vertex ordering expanded to the three coordinates: the same fill as ordering the 3n
  // graph, at a ninth of the cost.
  std::vector<std::int64_t> permutation(3 * static_cast<std::size_t>(m));
  for (std::size_t k = 0; k < vertices.permutation.size(); ++k)
    for (int c = 0; c < 3; ++c) permutation[3 * k + static_cast<std::size_t>(c)] = 3 * vertices.permutation[k] + c;
  try {
    cholesky.factorize(A, permutation);
  } catch (const std::runtime_error&) {
    throw std::runtime_error("vertex flow: the normal matrix is not positive definite");
  }
  report.seconds_factorization += seconds_since(start);

  start = Clock::now();
  Eigen::VectorXd rhs(3 * static_cast<Eigen::Index>(m));
  for (Index a = 0; a < m; ++a) block_at(rhs, a) = block_at(b, p.free_vertex[static_cast<std::size_t>(a)]);
  Eigen::VectorXd x;
  try {
    x = cholesky.solve(rhs);
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(std::string("vertex flow: ") + e.what());
  }
  BlockVector d = BlockVector::Zero(b.size());
  for (Index a = 0; a < m; ++a) block_at(d, p.free_vertex[static_cast<std::size_t>(a)]) = block_at(x, a);
  report.seconds_solve += seconds_since(start);
  return d;
}

FlowSystemSolver::FlowSystemSolver(const Topology& topology, std::vector<char> fixed, LinearSolver kind,
                                   double tolerance)
    : impl_(std::make_unique<Impl>(topology, std::move(fixed), kind, tolerance)) {
  if (!(tolerance > 0 && tolerance < 1)) throw std::invalid_argument("vertex flow: solver_tolerance must be in (0, 1)");
}

FlowSystemSolver::~FlowSystemSolver() = default;

const std::vector<Index>& FlowSystemSolver::vertex_order() const {
  return impl_->order;
}

void FlowSystemSolver::set_progress_phase(std::string phase) {
  impl_->progress_phase = std::move(phase);
}

Vertices FlowSystemSolver::solve(const FlowFrame& frame, const EnergyWeights& weights, FlowReport& report) {
  return solve(frame, nullptr, weights, report);
}

Vertices FlowSystemSolver::solve_releasing(FlowFrame& frame, const EnergyWeights& weights, FlowReport& report) {
  return solve(frame, &frame, weights, report);
}

Vertices FlowSystemSolver::solve(const FlowFrame& frame, FlowFrame* release, const EnergyWeights& weights,
                                 FlowReport& report) {
  Impl& s = *impl_;
  const Index m = s.num_free();
  auto start = Clock::now();
  s.number_vertices(frame.P);
  FlowTerms terms = make_flow_terms(s.topology, s.fixed, frame, weights, s.order);
  if (release) {  // only P is read from here on
    release->curvature = Curvature();
    std::vector<Eigen::Matrix3d>().swap(release->sliver_stiffness);
  }
  FlowOperator op(terms);  // exact products for b; the iterations may round (kFloatCachesFromTolerance)
  const BlockVector b = op.right_hand_side(to_local(terms, frame.P.data()));
  // The fairness targets enter b only: 24 bytes per vertex that the solve, the flow's peak, does
  // not read.
  std::vector<Eigen::Vector3d>().swap(terms.rest);
  report.seconds_assembly += seconds_since(start);

  bool direct = s.kind == LinearSolver::Direct || (s.kind == LinearSolver::Automatic && m <= kDirectBelow);
  BlockVector d;
  LinearSolver used = LinearSolver::Direct;
  report.solver_iterations = 0;
  if (!direct && m > 0) {
    start = Clock::now();
    op.release_caches();  // until the first iteration: the multilevel set-up is one of this path's peaks
    if (s.tolerance >= kFloatCachesFromTolerance) op.use_cache_precision(FlowOperator::CachePrecision::Float);
    std::unique_ptr<CoarseSpaceCorrection> multilevel;
    if (s.kind == LinearSolver::Multilevel ||
        (s.kind == LinearSolver::Automatic && has_flat_region(terms, kFlatCurvaturePerEdge, kFlatRegionForMultilevel)))
      multilevel = make_multilevel(terms);
    ConjugateGradients cg(op, block_jacobi(terms), b, multilevel.get());
    report.seconds_factorization += seconds_since(start);
    start = Clock::now();
    const int budget = static_cast<int>(std::ceil(kBudgetPerSqrtVertex * std::sqrt(static_cast<double>(m))));
    IterationResult result;
    double done = 0;  // of the iterations, for the progress
    if (s.kind == LinearSolver::Automatic && !multilevel) {
      // Block-Jacobi first; if the first iterations predict a long run, switch.
      result = run_reporting(cg, std::min(kProbeIterations, budget), s.tolerance, s.progress_phase, done);
      if (!result.converged && cg.predicted_iterations(kSwitchPredictedAt) > kSwitchAbovePredicted) {
        report.seconds_solve += seconds_since(start);
        start = Clock::now();
        op.release_caches();
        multilevel = make_multilevel(terms);
        if (multilevel) cg.use_correction(multilevel.get());
        report.seconds_factorization += seconds_since(start);
        start = Clock::now();
      }
    }
    if (!result.converged)
      result = run_reporting(
          cg, (s.kind == LinearSolver::Automatic ? budget : kIterationCapFactor * budget) - cg.total_iterations(),
          s.tolerance, s.progress_phase, done);
    if (!result.converged && s.kind == LinearSolver::Automatic) {
      // Fall back to the factorisation if it fits; otherwise keep iterating.
      report.seconds_solve += seconds_since(start);
      start = Clock::now();
      const double factor_entries = s.vertex_ordering(terms).factor_entries;
      report.seconds_factorization += seconds_since(start);
      start = Clock::now();
      if (9.0 * factor_entries * sizeof(double) <= kMaxFactorBytes) {
        direct = true;
      } else {
        result = run_reporting(cg, (kIterationCapFactor - 1) * budget, s.tolerance, s.progress_phase, done);
      }
    }
    report.seconds_solve += seconds_since(start);
    report.solver_iterations = cg.total_iterations();
    if (!direct) d = cg.take_solution();
    used = direct ? LinearSolver::Direct : multilevel ? LinearSolver::Multilevel : LinearSolver::Iterative;
  }
  if (direct && m > 0) d = s.factor_and_solve(terms, b, report);
  if (m == 0) d = BlockVector::Zero(b.size());
  report.solver_used = used;

  // The relative residual of the normal equations, independent of the method (exact products).
  start = Clock::now();
  op.use_cache_precision(FlowOperator::CachePrecision::Double);
  BlockVector residual(b.size());
  op.apply(d, residual);
  residual -= b;
  const double b_norm = std::sqrt(deterministic_dot(b, b));
  report.solver_error = b_norm > 0 ? std::sqrt(deterministic_dot(residual, residual)) / b_norm : 0.0;
  Vertices Y = copy_rows_in_parallel(frame.P);
  add_from_local(terms, d, Y.data());
  report.seconds_solve += seconds_since(start);
  return Y;
}

Vertices solve_flow_system(const Topology& topology, const FlowFrame& frame, const EnergyWeights& weights,
                           const std::vector<char>& fixed, FlowReport& report) {
  FlowSystemSolver solver(topology, fixed);
  return solver.solve(frame, weights, report);
}

}  // namespace vertexflow
