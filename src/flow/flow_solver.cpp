// Assembles the flow's least-squares system and solves its normal equations with a sparse
// Cholesky factorisation (CHOLMOD, supernodal).
#include "flow_solver.h"

#include <Eigen/CholmodSupport>
#include <Eigen/SparseCore>

#include <dlfcn.h>
#include <algorithm>
#include <chrono>
#include <stdexcept>

namespace vertexflow {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
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

}  // namespace

Vertices solve_flow_system(const Topology& topology, const FlowFrame& frame, const EnergyWeights& weights,
                           const std::vector<char>& fixed, FlowReport& report) {
  const Index n = static_cast<Index>(frame.P.rows());
  auto start = Clock::now();
  const LeastSquaresSystem system = assemble_flow_system(topology, frame, weights);
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
      if (c >= 0)
        triplets.emplace_back(static_cast<Index>(r), c, it.value());
      else
        rhs[r] -= it.value() * frame.P(it.col() / 3, it.col() % 3);
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
    if (cholesky.info() != Eigen::Success)
      throw std::runtime_error("vertex flow: the normal matrix is not positive definite");
    solution = cholesky.solve(normal_rhs);
    report.solver_error = (normal_matrix * solution - normal_rhs).norm() / std::max(normal_rhs.norm(), 1e-300);
  }
  Vertices Y = frame.P;
  for (Index i = 0; i < n; ++i) {
    for (int k = 0; k < 3; ++k) {
      const Index c = column[3 * static_cast<std::size_t>(i) + static_cast<std::size_t>(k)];
      if (c >= 0) Y(i, k) = solution[c];
    }
  }
  report.seconds_solve += seconds_since(start);
  return Y;
}

}  // namespace vertexflow
