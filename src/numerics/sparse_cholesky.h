// Internal: CHOLMOD's sparse Cholesky factorisation (SuiteSparse) for symmetric positive
// definite matrices given by their upper half in compressed columns.
//
// What it adds to CHOLMOD's own interface: ownership (no leaks on exceptions), failures as
// exceptions (std::bad_alloc when CHOLMOD runs out of memory, std::runtime_error otherwise;
// CHOLMOD prints nothing), a symbolic analysis reused while the pattern stays, and BLAS held
// to one thread.
//
// BLAS: the supernodal factorisation calls BLAS. Debian's default BLAS is the pthread build of
// OpenBLAS, whose results depend on its thread count (sums in a different order) and whose
// threads made the factorisation slower on 2 cores (docs/method-notes.md, "Solver facts"). So
// every factorisation first sets OpenBLAS (looked up at run time; any other BLAS works too) to
// one thread: the same bytes for every run. This sets the process-wide OpenBLAS thread count.
// Under an address-space limit (RLIMIT_AS or RLIMIT_DATA) the simplicial method, which needs
// no BLAS, is used instead: OpenBLAS spins forever when it cannot map its work buffer.
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

namespace vertexflow {

class SparseCholesky {
 public:
  SparseCholesky();
  ~SparseCholesky();
  SparseCholesky(const SparseCholesky&) = delete;
  SparseCholesky& operator=(const SparseCholesky&) = delete;

  /// A fill-reducing ordering of the symmetric pattern whose upper half has, in column c, the
  /// rows rows[column_start[c] .. column_start[c + 1]) (sorted, diagonal included): CHOLMOD's
  /// default choice (AMD, and METIS too when AMD fills badly).
  struct Ordering {
    std::vector<std::int64_t> permutation;  ///< new position -> old index
    double factor_entries = 0;              ///< predicted non-zeros of the factor
  };
  Ordering order(const std::vector<std::int64_t>& column_start, const std::vector<std::int32_t>& rows);

  /// A size x size symmetric matrix, upper half by columns, whose column starts are given; the
  /// caller fills rows() (sorted within each column) and values().
  class UpperMatrix {
   public:
    ~UpperMatrix();
    UpperMatrix(UpperMatrix&&) noexcept;
    UpperMatrix(const UpperMatrix&) = delete;
    UpperMatrix& operator=(const UpperMatrix&) = delete;
    UpperMatrix& operator=(UpperMatrix&&) = delete;
    std::span<std::int64_t> rows();
    std::span<double> values();

   private:
    friend class SparseCholesky;
    struct Data;
    explicit UpperMatrix(std::unique_ptr<Data> data);
    std::unique_ptr<Data> data_;
  };
  UpperMatrix allocate_upper(const std::vector<std::int64_t>& column_start);

  /// Factors A with the fill-reducing `permutation` (new position -> old index). The symbolic
  /// analysis of the first call is kept: later calls must pass a matrix of the same pattern.
  /// Throws std::runtime_error if A is not numerically positive definite.
  void factorize(UpperMatrix& A, const std::vector<std::int64_t>& permutation);

  /// A^-1 b with the last factorisation.
  Eigen::VectorXd solve(const Eigen::VectorXd& b);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace vertexflow
