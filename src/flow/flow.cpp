// Vertex flow: normalise, estimate curvature, assemble (flow_energy.cpp), solve the normal
// equations, then guard against flipped and degenerate faces.
#include "vertexflow/flow.h"

#include "vertexflow/flow_energy.h"
#include "vertexflow/statistics.h"
#include "vertexflow/topology.h"

#include <Eigen/CholmodSupport>
#include <Eigen/SparseCore>

#include <algorithm>
#include <dlfcn.h>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>

namespace vertexflow {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// The radius d of Eq. 6: 1 / (percentile of the largest |k| per vertex).
double robust_radius(const Curvature& c, double at_percentile) {
  std::vector<double> k(static_cast<std::size_t>(c.k1.size()));
  for (Eigen::Index i = 0; i < c.k1.size(); ++i) k[static_cast<std::size_t>(i)] = std::max(std::abs(c.k1[i]), std::abs(c.k2[i]));
  const double largest = percentile(std::move(k), at_percentile);
  return largest > 0 ? 1.0 / largest : 1.0;
}

// CHOLMOD's supernodal factorisation calls BLAS. Debian's default BLAS is the pthread build of
// OpenBLAS, whose results depend on its thread count (sums in a different order) and whose
// threads made the factorisation slower on this 2-core machine (method-notes, solver facts).
// One BLAS thread gives the same bytes for every run; looked up at run time so that any other
// BLAS works too.
void use_single_threaded_blas() {
  using SetThreads = void (*)(int);
  for (const char* name : {"openblas_set_num_threads", "goto_set_num_threads"}) {
    if (auto set = reinterpret_cast<SetThreads>(::dlsym(RTLD_DEFAULT, name))) {
      set(1);
      return;
    }
  }
}

// Faces that turned by more than 90 degrees or became degenerate.
// Faces already degenerate in `before` cannot be judged (no normal) and are never bad: the
// guard could not repair them, since returning their vertices to the input restores them.
std::vector<char> bad_faces(const Vertices& before, const Vertices& after, const Faces& F, double min_area) {
  std::vector<char> bad(static_cast<std::size_t>(F.rows()), 0);
  for (Index f = 0; f < F.rows(); ++f) {
    const Eigen::Vector3d n0 = face_normal(before, F, f), n1 = face_normal(after, F, f);
    if (0.5 * n0.norm() < min_area) continue;
    bad[static_cast<std::size_t>(f)] = n0.dot(n1) <= 0 || 0.5 * n1.norm() < min_area;
  }
  return bad;
}

// One solve: minimise the energy for positions X (normalised units), frozen curvature of X.
Vertices solve_once(const Vertices& X, const Faces& F, const Topology& topology, const std::vector<char>& fixed,
                    const FlowOptions& options, FlowReport& report) {
  const Index n = static_cast<Index>(X.rows());
  auto start = Clock::now();
  FlowFrame frame;
  frame.P = X;
  frame.curvature = principal_curvatures(X, F, topology, options.curvature);
  frame.d = robust_radius(frame.curvature, options.d_percentile);
  report.d = frame.d;
  report.seconds_curvature += seconds_since(start);

  start = Clock::now();
  const LeastSquaresSystem system = assemble_flow_system(topology, frame, {options.lambda, options.mu, options.epsilon});
  // Eliminate the fixed vertices: their columns move to the right-hand side.
  std::vector<Index> column(3 * static_cast<std::size_t>(n), -1);
  Index free_columns = 0;
  for (Index i = 0; i < n; ++i) {
    if (fixed[static_cast<std::size_t>(i)]) continue;
    for (int k = 0; k < 3; ++k) column[3 * static_cast<std::size_t>(i) + static_cast<std::size_t>(k)] = free_columns++;
  }
  Eigen::VectorXd rhs = system.b;
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(static_cast<std::size_t>(system.A.nonZeros()));
  for (Eigen::Index r = 0; r < system.A.outerSize(); ++r) {
    for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(system.A, r); it; ++it) {
      const Index c = column[static_cast<std::size_t>(it.col())];
      if (c >= 0) triplets.emplace_back(static_cast<Index>(r), c, it.value());
      else rhs[r] -= it.value() * X(it.col() / 3, it.col() % 3);
    }
  }
  Eigen::SparseMatrix<double> A_free(system.A.rows(), free_columns);
  A_free.setFromTriplets(triplets.begin(), triplets.end());
  const Eigen::SparseMatrix<double> normal_matrix = Eigen::SparseMatrix<double>(A_free.transpose()) * A_free;
  const Eigen::VectorXd normal_rhs = A_free.transpose() * rhs;
  report.seconds_assembly += seconds_since(start);

  start = Clock::now();
  // Sparse Cholesky of the normal equations (CHOLMOD, supernodal). Robust whatever the
  // conditioning; the coupled 3n x 3n factor fills in, so very large meshes want the
  // preconditioned iterative path planned in the flow issue.
  Eigen::VectorXd solution(free_columns);
  if (free_columns > 0) {
    use_single_threaded_blas();
    Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>, Eigen::Lower> cholesky;
    cholesky.compute(normal_matrix);
    if (cholesky.info() != Eigen::Success) throw std::runtime_error("vertex flow: the normal matrix is not positive definite");
    solution = cholesky.solve(normal_rhs);
    report.solver_error = (normal_matrix * solution - normal_rhs).norm() / std::max(normal_rhs.norm(), 1e-300);
  }
  Vertices Y = X;
  for (Index i = 0; i < n; ++i) {
    for (int k = 0; k < 3; ++k) {
      const Index c = column[3 * static_cast<std::size_t>(i) + static_cast<std::size_t>(k)];
      if (c >= 0) Y(i, k) = solution[c];
    }
  }
  if (!Y.allFinite()) throw std::runtime_error("vertex flow: the solver diverged");
  report.seconds_solve += seconds_since(start);
  return Y;
}

}  // namespace

std::vector<Index> flipped_faces(const Vertices& before, const Vertices& after, const Faces& F) {
  std::vector<Index> out;
  for (Index f = 0; f < F.rows(); ++f) {
    if (face_normal(before, F, f).dot(face_normal(after, F, f)) < 0) out.push_back(f);
  }
  return out;
}

std::vector<Index> degenerate_faces(const Vertices& V, const Faces& F) {
  const double diagonal = bounding_box(V).diagonal();
  const double min_area = kDegenerateAreaRelative * diagonal * diagonal;
  std::vector<Index> out;
  for (Index f = 0; f < F.rows(); ++f) {
    if (0.5 * face_normal(V, F, f).norm() < min_area) out.push_back(f);
  }
  return out;
}

FlowResult vertex_flow(const Vertices& V, const Faces& F, const FlowOptions& options) {
  const Index n = static_cast<Index>(V.rows());
  if (n == 0 || F.rows() == 0) throw std::invalid_argument("vertex flow: the mesh is empty");
  if (!(options.d_percentile >= 0 && options.d_percentile <= 100))
    throw std::invalid_argument("vertex flow: d_percentile must be in [0, 100]");
  if (options.max_halvings < 1) throw std::invalid_argument("vertex flow: max_halvings must be at least 1");
  const Topology topology = build_topology(F, n);
  if (!topology.is_manifold()) throw std::invalid_argument("vertex flow: " + describe_non_manifold(topology));
  FlowResult result;
  FlowReport& report = result.report;

  std::vector<char> fixed(static_cast<std::size_t>(n), 0);
  for (Index i = 0; i < n; ++i) {
    // Isolated vertices have no energy terms but the pull; keep them where they are.
    if ((options.fix_boundary && topology.is_boundary_vertex[static_cast<std::size_t>(i)]) || topology.valence(i) == 0)
      fixed[static_cast<std::size_t>(i)] = 1;
  }
  for (const Index p : options.pinned) {
    if (p < 0 || p >= n) throw std::invalid_argument("vertex flow: pinned vertex " + std::to_string(p) + " is out of range");
    fixed[static_cast<std::size_t>(p)] = 1;
  }
  report.fixed_vertices = static_cast<Index>(std::count(fixed.begin(), fixed.end(), 1));

  // Normalise: centroid at the origin, mean edge length 1.
  const Eigen::RowVector3d centroid = V.colwise().mean();
  report.mean_edge_length = mean_edge_length(V, topology);
  const double scale = report.mean_edge_length > 0 ? report.mean_edge_length : 1.0;
  const Vertices input = (V.rowwise() - centroid) / scale;

  Vertices X = input;
  for (int round = 0; round < std::max(1, options.iterations); ++round) X = solve_once(X, F, topology, fixed, options, report);

  // Flip guard: halve the displacement of every vertex of a bad face until no face is bad.
  const auto start = Clock::now();
  const double diagonal = bounding_box(input).diagonal();
  const double min_area = kDegenerateAreaRelative * diagonal * diagonal;
  const Vertices displacement = X - input;
  std::vector<double> step(static_cast<std::size_t>(n), 1.0);
  std::vector<char> bad = bad_faces(input, X, F, min_area);
  report.flipped_before_guard = static_cast<Index>(std::count(bad.begin(), bad.end(), 1));
  // Each round halves every free vertex of a bad face once; after max_halvings rounds their
  // displacement is zero, and a face whose vertices are all back at the input is not bad.
  std::vector<char> shortened(static_cast<std::size_t>(n), 0);
  for (int round = 1; std::count(bad.begin(), bad.end(), 1) > 0; ++round) {
    std::vector<char> in_bad_face(static_cast<std::size_t>(n), 0);
    for (Index f = 0; f < F.rows(); ++f) {
      if (!bad[static_cast<std::size_t>(f)]) continue;
      for (int k = 0; k < 3; ++k) in_bad_face[static_cast<std::size_t>(F(f, k))] = 1;
    }
    for (Index i = 0; i < n; ++i) {
      const auto v = static_cast<std::size_t>(i);
      if (!in_bad_face[v] || fixed[v]) continue;
      step[v] = round >= options.max_halvings ? 0.0 : 0.5 * step[v];
      shortened[v] = 1;
      X.row(i) = input.row(i) + step[v] * displacement.row(i);
    }
    bad = bad_faces(input, X, F, min_area);
  }
  report.limited_vertices = static_cast<Index>(std::count(shortened.begin(), shortened.end(), 1));
  report.d *= scale;
  report.seconds_guard = seconds_since(start);

  result.V = (X * scale).rowwise() + centroid;
  // Fixed vertices are returned bit for bit.
  for (Index i = 0; i < n; ++i) {
    if (fixed[static_cast<std::size_t>(i)]) result.V.row(i) = V.row(i);
  }
  return result;
}

}  // namespace vertexflow
