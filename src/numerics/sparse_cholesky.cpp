#include "numerics/sparse_cholesky.h"

#include <cholmod.h>
#include <dlfcn.h>
#include <sys/resource.h>

#include <algorithm>
#include <mutex>
#include <new>
#include <stdexcept>
#include <type_traits>

namespace vertexflow {
namespace {

static_assert(std::is_same_v<SuiteSparse_long, std::int64_t>, "CHOLMOD's long indices are the header's int64");

// One BLAS thread (sparse_cholesky.h).
void use_single_threaded_blas() {
  using SetThreads = void (*)(int);
  for (const char* name : {"openblas_set_num_threads", "goto_set_num_threads"}) {
    if (auto set = reinterpret_cast<SetThreads>(::dlsym(RTLD_DEFAULT, name))) {
      set(1);
      return;
    }
  }
}

// CHOLMOD calls take turns across the process. Two things are not safe to run from two threads
// at once: CHOLMOD's default ordering tries METIS, whose random number state is global, and
// Debian's serial OpenBLAS (the BLAS of the supernodal factorisation) is not built for
// concurrent callers. Measured with `batch --manifest M --jobs 2` over four reference fits
// (each round factorises): without turns, amo_adaptive's output had 3 different hashes in 4 runs
// (bunny_adaptive's 2); with only the orderings taking turns, amo_adaptive failed in 1 run of 5
// as "not positive definite". A batch's jobs still overlap
// everything else (queries, the guard, I/O); the factorisations of a fit are 30% of its time.
std::mutex& cholmod_mutex() {
  static std::mutex mutex;
  return mutex;
}

bool address_space_is_limited() {
  for (const int resource : {RLIMIT_AS, RLIMIT_DATA}) {
    rlimit limit{};
    if (::getrlimit(resource, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY) return true;
  }
  return false;
}

// CHOLMOD reports running out of memory in its status; everything else is a numerical failure.
void throw_if_out_of_memory(const cholmod_common& common) {
  if (common.status == CHOLMOD_OUT_OF_MEMORY || common.status == CHOLMOD_TOO_LARGE) throw std::bad_alloc();
}

}  // namespace

struct SparseCholesky::Impl {
  cholmod_common common{};
  cholmod_factor* factor = nullptr;

  Impl() {
    cholmod_l_start(&common);
    common.supernodal = address_space_is_limited() ? CHOLMOD_SIMPLICIAL : CHOLMOD_SUPERNODAL;
    common.print = 0;  // failures become exceptions, never CHOLMOD's own prints
  }
  ~Impl() {
    if (factor) cholmod_l_free_factor(&factor, &common);
    cholmod_l_finish(&common);
  }
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;
};

struct SparseCholesky::UpperMatrix::Data {
  cholmod_common* common = nullptr;
  cholmod_sparse* matrix = nullptr;
  ~Data() {
    if (matrix) cholmod_l_free_sparse(&matrix, common);
  }
};

SparseCholesky::UpperMatrix::UpperMatrix(std::unique_ptr<Data> data) : data_(std::move(data)) {}
SparseCholesky::UpperMatrix::UpperMatrix(UpperMatrix&&) noexcept = default;
SparseCholesky::UpperMatrix::~UpperMatrix() = default;

std::span<std::int64_t> SparseCholesky::UpperMatrix::rows() {
  return {static_cast<std::int64_t*>(data_->matrix->i), data_->matrix->nzmax};
}
std::span<double> SparseCholesky::UpperMatrix::values() {
  return {static_cast<double*>(data_->matrix->x), data_->matrix->nzmax};
}

SparseCholesky::SparseCholesky() : impl_(std::make_unique<Impl>()) {}
SparseCholesky::~SparseCholesky() = default;

SparseCholesky::Ordering SparseCholesky::order(const std::vector<std::int64_t>& column_start,
                                               const std::vector<std::int32_t>& rows) {
  cholmod_common& common = impl_->common;
  const std::size_t m = column_start.size() - 1;
  cholmod_sparse* pattern = cholmod_l_allocate_sparse(m, m, rows.size(), 1, 1, 1, CHOLMOD_PATTERN, &common);
  if (!pattern) throw std::bad_alloc();
  std::copy(column_start.begin(), column_start.end(), static_cast<SuiteSparse_long*>(pattern->p));
  std::copy(rows.begin(), rows.end(), static_cast<SuiteSparse_long*>(pattern->i));
  common.nmethods = 0;  // CHOLMOD's default strategy
  common.postorder = 1;
  cholmod_factor* symbolic = nullptr;
  {
    const std::lock_guard lock(cholmod_mutex());
    symbolic = cholmod_l_analyze(pattern, &common);
  }
  cholmod_l_free_sparse(&pattern, &common);
  if (!symbolic) {
    throw_if_out_of_memory(common);
    throw std::runtime_error("CHOLMOD could not order the matrix");
  }
  Ordering ordering;
  ordering.factor_entries = common.lnz;
  const auto* perm = static_cast<const SuiteSparse_long*>(symbolic->Perm);
  ordering.permutation.assign(perm, perm + m);
  cholmod_l_free_factor(&symbolic, &common);
  return ordering;
}

SparseCholesky::UpperMatrix SparseCholesky::allocate_upper(const std::vector<std::int64_t>& column_start) {
  cholmod_common& common = impl_->common;
  const std::size_t size = column_start.size() - 1;
  auto data = std::make_unique<UpperMatrix::Data>();
  data->common = &common;
  data->matrix = cholmod_l_allocate_sparse(size, size, static_cast<std::size_t>(column_start.back()), 1, 1, 1,
                                           CHOLMOD_REAL, &common);
  if (!data->matrix) throw std::bad_alloc();
  std::copy(column_start.begin(), column_start.end(), static_cast<SuiteSparse_long*>(data->matrix->p));
  return UpperMatrix(std::move(data));
}

void SparseCholesky::factorize(UpperMatrix& A, const std::vector<std::int64_t>& permutation) {
  cholmod_common& common = impl_->common;
  const std::lock_guard lock(cholmod_mutex());
  use_single_threaded_blas();
  if (!impl_->factor) {
    common.nmethods = 1;
    common.method[0].ordering = CHOLMOD_GIVEN;
    common.postorder = 1;
    impl_->factor =
        cholmod_l_analyze_p(A.data_->matrix, const_cast<SuiteSparse_long*>(permutation.data()), nullptr, 0, &common);
  }
  const bool ok =
      impl_->factor && cholmod_l_factorize(A.data_->matrix, impl_->factor, &common) && common.status == CHOLMOD_OK;
  throw_if_out_of_memory(common);
  if (!ok) throw std::runtime_error("the matrix is not positive definite");
}

Eigen::VectorXd SparseCholesky::solve(const Eigen::VectorXd& b) {
  cholmod_common& common = impl_->common;
  const auto size = static_cast<std::size_t>(b.size());
  cholmod_dense* rhs = cholmod_l_allocate_dense(size, 1, size, CHOLMOD_REAL, &common);
  if (!rhs) throw std::bad_alloc();
  std::copy(b.data(), b.data() + b.size(), static_cast<double*>(rhs->x));
  cholmod_dense* x = nullptr;
  {
    const std::lock_guard lock(cholmod_mutex());
    x = cholmod_l_solve(CHOLMOD_A, impl_->factor, rhs, &common);
  }
  cholmod_l_free_dense(&rhs, &common);
  throw_if_out_of_memory(common);
  if (!x) throw std::runtime_error("CHOLMOD's triangular solves failed");
  Eigen::VectorXd out = Eigen::Map<const Eigen::VectorXd>(static_cast<const double*>(x->x), b.size());
  cholmod_l_free_dense(&x, &common);
  return out;
}

}  // namespace vertexflow
