#include "numerics/multigrid.h"

#include "common/bucket_by_key.h"
#include "numerics/block3.h"
#include "numerics/parallel.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <utility>

namespace vertexflow {
namespace {

using Matrix3 = Eigen::Matrix3d;
using Vector3 = Eigen::Vector3d;

// Strength of connection between nodes (Vanek et al.): |A_kl|_F >= theta sqrt(|A_kk|_F |A_ll|_F).
// Weak couplings would glue aggregates across the anisotropy and are left out of the graph.
constexpr double kStrengthThreshold = 0.08;
// Power iterations for the spectral radius of B A in the prolongator's damping.
constexpr int kPowerIterations = 12;
// Blocks of a prolongator row below this fraction of the row's largest are dropped and lumped
// into the row's own aggregate (smoothed_prolongator). The value usual for truncated
// interpolation in algebraic multigrid; measured against none (iterations, `--solver multilevel`,
// the 1e-4 tolerance): the 1M armadillo 48 -> 46 and its set-up 2.7 -> 1.8 s, fandisk split to
// 932k vertices 155 -> 136, chamfer-cube split to 141k 125 -> 113, fandisk 59 -> 53, the other
// data meshes the same or one more; at 10M 70 -> 72 iterations, the set-up 21-23 -> 18.2 s and
// the peak 7.97 -> 7.28 GB (docs/benchmarks.md, "Truncated prolongators"). 0.3 lost the grid
// bi-Laplacian's test below.
constexpr double kProlongatorTruncation = 0.1;
// The largest coarsest level factored densely (1,500 unknowns: 18 MB, about 1e9 flops).
constexpr Eigen::Index kLargestDenseCoarsest = 1500;

// Rows in the calling thread below this many: the coarse levels are applied once per outer
// iteration, and for a few hundred rows starting tasks cost more than the rows.
constexpr int kSerialBelow = 2048;

template <class Body>
void parallel_rows(int rows, Body&& body) {
  parallel_for_index(rows, body, 128, kSerialBelow);
}

// Fixed chunks of rows for transpose below: the result does not depend on them, and four
// keep the per-chunk column counts small (4 ints per column) while two threads share the work.
constexpr std::size_t kTransposeChunks = 4;

// A^T: the blocks (r, c) of A, bucketed by column c in order of r (the places of the serial loop
// over rows), written transposed. Counted and placed by fixed chunks of rows in parallel
// (place_by_key_in_chunks): this transpose on one core was 1.5 s of the hierarchy's set-up at
// 10M vertices, with the page faults of first writing the result (docs/benchmarks.md).
template <class Scalar>
BasicBlockSparseMatrix<Scalar> transpose(const BasicBlockSparseMatrix<Scalar>& A) {
  BasicBlockSparseMatrix<Scalar> T;
  T.rows = A.cols;
  T.cols = A.rows;
  T.start = place_by_key_in_chunks<int>(
      static_cast<std::size_t>(A.cols), kTransposeChunks,
      [&](std::size_t chunk, auto&& emit) {  // block m of row r as (r, m), keyed by its column
        const auto [first, last] = chunk_range(static_cast<std::size_t>(A.rows), kTransposeChunks, chunk);
        for (auto r = static_cast<int>(first); r < static_cast<int>(last); ++r)
          for (int m = A.start[static_cast<std::size_t>(r)]; m < A.start[static_cast<std::size_t>(r) + 1]; ++m)
            emit(static_cast<std::size_t>(A.column[static_cast<std::size_t>(m)]), std::pair{r, m});
      },
      [&](std::size_t total) {
        T.column.resize(total);
        T.block.resize(total);  // not initialised: each block is written once
      },
      [&](std::size_t at, const std::pair<int, int>& block) {
        T.column[at] = block.first;
        T.block[at] = A.block[static_cast<std::size_t>(block.second)].transpose();
      });
  return T;
}

// The set-up reads a symmetric matrix by rows, either stored whole (BlockSparseMatrix) or as
// its upper half (UpperHalf): for_each_in_row(A, k, visit) calls visit(column, block) for the
// blocks of row k in column order, with the same values either way, so that a level built from
// the upper half is the same bytes as one built from the whole matrix.
template <class Visit>
void for_each_in_row(const BlockSparseMatrix& A, int k, Visit&& visit) {
  for (int m = A.start[static_cast<std::size_t>(k)]; m < A.start[static_cast<std::size_t>(k) + 1]; ++m)
    visit(A.column[static_cast<std::size_t>(m)], A.block[static_cast<std::size_t>(m)]);
}

// A symmetric matrix from its upper half (diagonal included) and, for each row k, the places of
// the upper half's blocks (r, k), r < k, in order of r: row k's strictly lower blocks are their
// transposes. 8 bytes per such block, where the whole matrix would take another 72 + 4: the
// whole first coarse matrix was the flow's peak memory on large meshes (docs/benchmarks.md).
struct UpperHalf {
  explicit UpperHalf(const BlockSparseMatrix& upper_half)
      : upper(upper_half),
        rows(upper.rows),
        cols(upper.cols),
        lower(bucket_by_key<std::pair<int, int>, int>(static_cast<std::size_t>(rows), [&](auto&& emit) {
          for (int r = 0; r < rows; ++r)
            for (int m = upper.start[static_cast<std::size_t>(r)]; m < upper.start[static_cast<std::size_t>(r) + 1];
                 ++m)
              if (const int c = upper.column[static_cast<std::size_t>(m)]; c != r)
                emit(static_cast<std::size_t>(c), std::pair{r, m});
        })) {}
  const BlockSparseMatrix& upper;
  int rows, cols;
  KeyBuckets<std::pair<int, int>, int> lower;  // per row k: (row r, place of block (r, k) in upper)
};

template <class Visit>
void for_each_in_row(const UpperHalf& A, int k, Visit&& visit) {
  const auto row = static_cast<std::size_t>(k);
  for (int p = A.lower.start[row]; p < A.lower.start[row + 1]; ++p) {
    const auto [r, m] = A.lower.items[static_cast<std::size_t>(p)];
    const Matrix3 block = A.upper.block[static_cast<std::size_t>(m)].transpose();
    visit(r, block);
  }
  for_each_in_row(A.upper, k, visit);
}

// y = A x, as BlockSparseMatrix::multiply sums it. Not folded with that member, which also
// applies the hierarchy's float blocks: its product with the lazily cast block rounds
// differently from one with a block first copied to double (the outputs' bytes would change).
template <class Rows>
void multiply(const Rows& A, const Eigen::VectorXd& x, Eigen::VectorXd& y) {
  y.resize(3 * static_cast<Eigen::Index>(A.rows));
  parallel_rows(A.rows, [&](int k) {
    Vector3 sum = Vector3::Zero();
    for_each_in_row(A, k, [&](int column, const Matrix3& block) { sum.noalias() += block * block_at(x, column); });
    block_at(y, k) = sum;
  });
}

// A's diagonal block k, or null if the row has none: row k of a whole matrix scanned, or the
// first block of the upper half's row (its lower part, transposed on the fly, holds none).
const Matrix3* diagonal_block(const BlockSparseMatrix& A, int k) {
  for (int m = A.start[static_cast<std::size_t>(k)]; m < A.start[static_cast<std::size_t>(k) + 1]; ++m)
    if (A.column[static_cast<std::size_t>(m)] == k) return &A.block[static_cast<std::size_t>(m)];
  return nullptr;
}
const Matrix3* diagonal_block(const UpperHalf& A, int k) {
  return diagonal_block(A.upper, k);
}

// Fixed chunks of rows for strength_graph: the graph does not depend on them.
constexpr int kStrengthChunks = 64;

// The strong-connection graph of A's blocks, CSR. Each fixed chunk of rows is listed by one task
// and the lists are joined in order, so the graph is that of one serial pass (1.27M rows of the
// 10M armadillo's first coarse level: 0.44 s serial).
template <class Rows>
void strength_graph(const Rows& A, std::vector<int>& start, std::vector<int>& neighbours) {
  const auto rows = static_cast<std::size_t>(A.rows);
  std::vector<double> diagonal(rows, 0.0);
  parallel_rows(A.rows, [&](int k) {
    if (const Matrix3* block = diagonal_block(A, k)) diagonal[static_cast<std::size_t>(k)] = block->norm();
  });
  std::vector<int> row_size(rows, 0);
  std::vector<std::vector<int>> chunk(kStrengthChunks);
  tbb::parallel_for(0, kStrengthChunks, [&](int c) {
    const auto [first, last] = chunk_range(rows, kStrengthChunks, static_cast<std::size_t>(c));
    std::vector<int>& list = chunk[static_cast<std::size_t>(c)];
    for (auto k = static_cast<int>(first); k < static_cast<int>(last); ++k) {
      const std::size_t before = list.size();
      for_each_in_row(A, k, [&](int l, const Matrix3& block) {
        if (l == k) return;
        const double bound = kStrengthThreshold * kStrengthThreshold * diagonal[static_cast<std::size_t>(k)] *
                             diagonal[static_cast<std::size_t>(l)];
        if (block.squaredNorm() >= bound) list.push_back(l);
      });
      row_size[static_cast<std::size_t>(k)] = static_cast<int>(list.size() - before);
    }
  });
  start.assign(rows + 1, 0);
  for (std::size_t k = 0; k < rows; ++k) start[k + 1] = start[k] + row_size[k];
  neighbours.clear();
  neighbours.reserve(static_cast<std::size_t>(start[rows]));
  for (std::vector<int>& list : chunk) {
    neighbours.insert(neighbours.end(), list.begin(), list.end());
    std::vector<int>().swap(list);
  }
}

template <class Rows>
std::vector<Matrix3> block_diagonal_inverse(const Rows& A) {
  std::vector<Matrix3> inverse(static_cast<std::size_t>(A.rows), Matrix3::Zero());
  parallel_rows(A.rows, [&](int k) {
    if (const Matrix3* block = diagonal_block(A, k)) inverse[static_cast<std::size_t>(k)] = block->inverse();
  });
  return inverse;
}

// Largest eigenvalue of B A (similar to a symmetric matrix), by power iteration from a fixed
// start.
template <class Rows>
double spectral_radius(const std::vector<Matrix3>& inverse_diagonal, const Rows& A) {
  Eigen::VectorXd v(3 * static_cast<Eigen::Index>(A.rows)), w;
  for (Eigen::Index k = 0; k < v.size(); ++k) v[k] = 1.0 + 0.5 * std::sin(0.7 * static_cast<double>(k));
  double lambda = 1;
  for (int iteration = 0; iteration < kPowerIterations; ++iteration) {
    multiply(A, v, w);
    parallel_rows(A.rows,
                  [&](int k) { block_at(w, k) = inverse_diagonal[static_cast<std::size_t>(k)] * block_at(w, k); });
    lambda = w.norm() / v.norm();
    v = w / w.norm();
  }
  return lambda;
}

// The tentative prolongator's unit-length columns: phi_a = I / sqrt(|a|) on each node of
// aggregate a; returns 1 / sqrt(|a|) per aggregate.
std::vector<double> aggregate_scales(const std::vector<int>& aggregate, int count) {
  std::vector<double> scale(static_cast<std::size_t>(count), 0.0);
  for (const int a : aggregate) scale[static_cast<std::size_t>(a)] += 1;
  for (double& s : scale) s = 1.0 / std::sqrt(s);
  return scale;
}

template <class Rows>
BlockSparseMatrix smoothed_prolongator_of(const Rows& A, const std::vector<int>& aggregate, int count,
                                          const std::vector<Eigen::Matrix3d>& block_inverse, double omega,
                                          double truncation) {
  const std::vector<double> scale = aggregate_scales(aggregate, count);
  tbb::enumerable_thread_specific<std::vector<std::pair<int, Matrix3>>> scratch;
  return build_block_rows(A.rows, count, [&](int k, BlockRowAccumulator& row) {
    // The row's blocks by aggregate, summed in A's column order (a handful: linear search).
    std::vector<std::pair<int, Matrix3>>& blocks = scratch.local();
    blocks.clear();
    auto at = [&](int b) -> Matrix3& {
      for (auto& [column, block] : blocks)
        if (column == b) return block;
      return blocks.emplace_back(b, Matrix3::Zero()).second;
    };
    const auto own = aggregate[static_cast<std::size_t>(k)];
    at(own).diagonal().array() += scale[static_cast<std::size_t>(own)];
    const Matrix3 damped = omega * block_inverse[static_cast<std::size_t>(k)];
    for_each_in_row(A, k, [&](int column, const Matrix3& block) {
      const auto b = aggregate[static_cast<std::size_t>(column)];
      at(b).noalias() -= scale[static_cast<std::size_t>(b)] * (damped * block);
    });
    double largest = 0;
    for (const auto& entry : blocks) largest = std::max(largest, entry.second.norm());
    // The coarse translation is t / scale_b at aggregate b, on which a dropped block B acted as
    // B t / scale_b; B scale_own / scale_b added to the own column acts the same on t / scale_own
    // (multigrid.h: P maps the coarse translations as without truncation).
    Matrix3 lumped = Matrix3::Zero();
    for (const auto& [column, block] : blocks) {
      if (column != own && block.norm() < truncation * largest)
        lumped += block * (scale[static_cast<std::size_t>(own)] / scale[static_cast<std::size_t>(column)]);
      else
        row[column] += block;
    }
    row[own] += lumped;
  });
}

}  // namespace

BlockSparseMatrix smoothed_prolongator(const BlockSparseMatrix& A, const std::vector<int>& aggregate, int count,
                                       const std::vector<Eigen::Matrix3d>& block_inverse, double omega,
                                       double truncation) {
  return smoothed_prolongator_of(A, aggregate, count, block_inverse, omega, truncation);
}

BlockRowAccumulator::BlockRowAccumulator(int cols) : position_(static_cast<std::size_t>(cols), -1) {}

Matrix3& BlockRowAccumulator::operator[](int column) {
  int& p = position_[static_cast<std::size_t>(column)];
  if (p < 0) {
    p = static_cast<int>(entries_.size());
    entries_.emplace_back(column, Matrix3::Zero());
  }
  return entries_[static_cast<std::size_t>(p)].second;
}

int BlockRowAccumulator::append_to(std::vector<int>& column, std::vector<Matrix3>& block) {
  for (const auto& entry : entries_) position_[static_cast<std::size_t>(entry.first)] = -1;
  std::sort(entries_.begin(), entries_.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  for (const auto& [c, b] : entries_) {
    column.push_back(c);
    block.push_back(b);
  }
  const auto appended = static_cast<int>(entries_.size());
  entries_.clear();
  return appended;
}

namespace {

// Rows built by one task, compressed: row j of the chunk holds the blocks [start[j], start[j + 1]).
struct RowChunk {
  std::vector<int> start;
  std::vector<int> column;
  std::vector<Matrix3> block;
};

// Rows per task of build_row_chunks.
constexpr int kRowsPerChunk = 64;

// Rows body(0), ..., body(count - 1), built by tasks in fixed chunks of kRowsPerChunk rows into
// chunks[0, 1, ...]: one allocation per chunk, reused from call to call, instead of one per row.
// A row per allocation, appended to the matrix and freed by the calling thread, cost about 7 s
// of the hierarchy set-up's 41 s of main-thread samples at 10M vertices, page faults, frees
// and the append on one core (docs/benchmarks.md).
void build_row_chunks(int count, const std::function<void(int, BlockRowAccumulator&)>& body,
                      tbb::enumerable_thread_specific<BlockRowAccumulator>& accumulators,
                      std::vector<RowChunk>& chunks) {
  const int num_chunks = (count + kRowsPerChunk - 1) / kRowsPerChunk;
  if (chunks.size() < static_cast<std::size_t>(num_chunks)) chunks.resize(static_cast<std::size_t>(num_chunks));
  tbb::parallel_for(0, num_chunks, [&](int c) {
    RowChunk& chunk = chunks[static_cast<std::size_t>(c)];
    chunk.start.assign(1, 0);
    chunk.column.clear();
    chunk.block.clear();
    BlockRowAccumulator& accumulator = accumulators.local();
    for (int k = c * kRowsPerChunk; k < std::min(count, (c + 1) * kRowsPerChunk); ++k) {
      body(k, accumulator);
      chunk.start.push_back(chunk.start.back() + accumulator.append_to(chunk.column, chunk.block));
    }
  });
}

// Appends the first `count` rows of `chunks` to the compressed rows (start, column, block),
// copied into place in parallel so that the first writes of the matrix's pages are shared by
// the threads. `reserve(blocks)` may reserve the arrays first, given the count of new blocks.
void append_row_chunks(int count, const std::vector<RowChunk>& chunks, std::vector<int>& start,
                       std::vector<int>& column, std::vector<Matrix3>& block,
                       const std::function<void(std::size_t)>& reserve) {
  const int num_chunks = (count + kRowsPerChunk - 1) / kRowsPerChunk;
  std::vector<std::size_t> offset(static_cast<std::size_t>(num_chunks) + 1, static_cast<std::size_t>(start.back()));
  for (int c = 0; c < num_chunks; ++c) {
    const RowChunk& chunk = chunks[static_cast<std::size_t>(c)];
    const int base = start.back();
    for (std::size_t j = 1; j < chunk.start.size(); ++j) start.push_back(base + chunk.start[j]);
    offset[static_cast<std::size_t>(c) + 1] = offset[static_cast<std::size_t>(c)] + chunk.column.size();
  }
  if (reserve) reserve(offset.back() - offset.front());
  column.resize(offset.back());
  block.resize(offset.back());  // Eigen's fixed-size matrices are not initialised: no pass
  tbb::parallel_for(0, num_chunks, [&](int c) {
    const RowChunk& chunk = chunks[static_cast<std::size_t>(c)];
    const auto at = static_cast<std::ptrdiff_t>(offset[static_cast<std::size_t>(c)]);
    std::copy(chunk.column.begin(), chunk.column.end(), column.begin() + at);
    std::copy(chunk.block.begin(), chunk.block.end(), block.begin() + at);
  });
}

}  // namespace

BlockSparseMatrix build_block_rows(int rows, int cols, const std::function<void(int, BlockRowAccumulator&)>& body,
                                   int range_rows, const std::function<void(int, int)>& prepare) {
  // Rows are built a range at a time and appended, so that rows under construction exist for
  // one range only: all of them beside the finished matrix were twice its size, the peak of the
  // multilevel set-up on large meshes (docs/benchmarks.md). The first range's density sizes the
  // arrays (with a margin), so that they rarely grow, and never by copying most of the matrix.
  BlockSparseMatrix A;
  A.rows = rows;
  A.cols = cols;
  A.start.reserve(static_cast<std::size_t>(rows) + 1);
  tbb::enumerable_thread_specific<BlockRowAccumulator> accumulators([cols] { return BlockRowAccumulator(cols); });
  std::vector<RowChunk> chunks;
  for (int r0 = 0; r0 < rows; r0 += range_rows) {
    const int r1 = std::min(rows, r0 + range_rows);
    if (prepare) prepare(r0, r1);
    auto reserve = [&](std::size_t blocks) {
      if (r0 > 0) return;
      const double per_row = static_cast<double>(blocks) / (r1 - r0);
      const auto expected = static_cast<std::size_t>(1.05 * per_row * rows) + blocks;
      A.column.reserve(expected);
      A.block.reserve(expected);
    };
    build_row_chunks(
        r1 - r0, [&](int k, BlockRowAccumulator& row) { body(r0 + k, row); }, accumulators, chunks);
    append_row_chunks(r1 - r0, chunks, A.start, A.column, A.block, reserve);
  }
  return A;
}

BlockSparseMatrix symmetric_from_upper(const BlockSparseMatrix& upper) {
  // Row k as the set-up reads it from the upper half (UpperHalf): the transposes of upper's
  // blocks (r, k), r < k, in order of r, then row k of upper; both parts are sorted, so the row
  // is. Written straight into place, each row by one task.
  const UpperHalf half(upper);
  const auto rows = static_cast<std::size_t>(upper.rows);
  BlockSparseMatrix S;
  S.rows = upper.rows;
  S.cols = upper.cols;
  S.start.assign(rows + 1, 0);
  for (std::size_t k = 0; k < rows; ++k)
    S.start[k + 1] =
        S.start[k] + (half.lower.start[k + 1] - half.lower.start[k]) + (upper.start[k + 1] - upper.start[k]);
  S.column.resize(static_cast<std::size_t>(S.start.back()));
  S.block.resize(static_cast<std::size_t>(S.start.back()));
  parallel_rows(upper.rows, [&](int k) {
    auto out = static_cast<std::size_t>(S.start[static_cast<std::size_t>(k)]);
    for_each_in_row(half, k, [&](int column, const Matrix3& block) {
      S.column[out] = column;
      S.block[out++] = block;
    });
  });
  return S;
}

template <class Scalar>
void BasicBlockSparseMatrix<Scalar>::multiply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const {
  y.resize(3 * static_cast<Eigen::Index>(rows));
  parallel_rows(rows, [&](int k) {
    Vector3 sum = Vector3::Zero();
    for (int m = start[static_cast<std::size_t>(k)]; m < start[static_cast<std::size_t>(k) + 1]; ++m)
      sum.noalias() +=
          block[static_cast<std::size_t>(m)].template cast<double>() * block_at(x, column[static_cast<std::size_t>(m)]);
    block_at(y, k) = sum;
  });
}
template struct BasicBlockSparseMatrix<double>;
template struct BasicBlockSparseMatrix<float>;

FloatBlockSparseMatrix rounded_to_float(const BlockSparseMatrix& A) {
  FloatBlockSparseMatrix F;
  F.rows = A.rows;
  F.cols = A.cols;
  F.start = A.start;
  F.column = A.column;
  F.block.resize(A.block.size());
  parallel_rows(static_cast<int>(A.block.size()), [&](int m) {
    F.block[static_cast<std::size_t>(m)] = A.block[static_cast<std::size_t>(m)].cast<float>();
  });
  return F;
}

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

namespace {

// The Galerkin matrix R (A P), a range of its rows at a time from the rows of A P that range
// needs only: A P whole was as large as A, and beside A, P and R the peak of the hierarchy's
// set-up. Each row of A P and each block of the product is summed in the order of the whole
// product, so the result is the same.
template <class Rows, class Scalar>
BlockSparseMatrix galerkin_product(const Rows& A, const BasicBlockSparseMatrix<Scalar>& P,
                                   const BasicBlockSparseMatrix<Scalar>& R) {
  std::vector<int> slot(static_cast<std::size_t>(A.rows), -1);  // row of A P -> its row in `ap`
  std::vector<int> needed;
  std::vector<RowChunk> ap;  // the rows `needed` of A P, kRowsPerChunk to a chunk
  tbb::enumerable_thread_specific<BlockRowAccumulator> accumulators([&] { return BlockRowAccumulator(P.cols); });
  // Before each range of coarse rows: the rows of A P it reads, in place of the last range's.
  auto prepare = [&](int i0, int i1) {
    for (const int k : needed) slot[static_cast<std::size_t>(k)] = -1;
    needed.clear();
    for (int m = R.start[static_cast<std::size_t>(i0)]; m < R.start[static_cast<std::size_t>(i1)]; ++m) {
      const int k = R.column[static_cast<std::size_t>(m)];
      if (slot[static_cast<std::size_t>(k)] < 0) {
        slot[static_cast<std::size_t>(k)] = static_cast<int>(needed.size());
        needed.push_back(k);
      }
    }
    build_row_chunks(
        static_cast<int>(needed.size()),
        [&](int t, BlockRowAccumulator& row) {
          for_each_in_row(A, needed[static_cast<std::size_t>(t)], [&](int l, const Matrix3& a) {
            for (int q = P.start[static_cast<std::size_t>(l)]; q < P.start[static_cast<std::size_t>(l) + 1]; ++q)
              row[P.column[static_cast<std::size_t>(q)]].noalias() +=
                  a * P.block[static_cast<std::size_t>(q)].template cast<double>();
          });
        },
        accumulators, ap);
  };
  return build_block_rows(
      R.rows, P.cols,
      [&](int i, BlockRowAccumulator& row) {
        for (int m = R.start[static_cast<std::size_t>(i)]; m < R.start[static_cast<std::size_t>(i) + 1]; ++m) {
          const Matrix3 left = R.block[static_cast<std::size_t>(m)].template cast<double>();
          const auto t =
              static_cast<std::size_t>(slot[static_cast<std::size_t>(R.column[static_cast<std::size_t>(m)])]);
          const RowChunk& chunk = ap[t / kRowsPerChunk];
          const std::size_t j = t % kRowsPerChunk;
          for (int q = chunk.start[j]; q < chunk.start[j + 1]; ++q)
            row[chunk.column[static_cast<std::size_t>(q)]].noalias() += left * chunk.block[static_cast<std::size_t>(q)];
        }
      },
      8192, prepare);
}

// The tentative prolongator in float: row k one block s I in column aggregate[k], s = 1 /
// sqrt(|a|) (smoothed_prolongator's P_t, the blocks it would give with omega 0, rounded).
FloatBlockSparseMatrix tentative_prolongator(const std::vector<int>& aggregate, int count) {
  const std::vector<double> scale = aggregate_scales(aggregate, count);
  FloatBlockSparseMatrix P;
  P.rows = static_cast<int>(aggregate.size());
  P.cols = count;
  P.start.resize(aggregate.size() + 1);
  P.column = aggregate;
  P.block.resize(aggregate.size());
  parallel_rows(P.rows, [&](int k) {
    const auto row = static_cast<std::size_t>(k);
    P.start[row + 1] = k + 1;
    const auto s = static_cast<float>(scale[static_cast<std::size_t>(aggregate[row])]);
    P.block[row] = Eigen::Matrix3f::Zero();
    P.block[row].diagonal().setConstant(s);
  });
  return P;
}

// R A P for a tentative prolongator (one block s I per row; R = P^T): galerkin_product's sums in
// its order, with its products by s I done as products by s (the same values: the other terms
// of each entry were products by zero). Row a of R A P sums, over the nodes k of aggregate a in
// order, s_a times row k of A P, whose block b sums s_b A_kl over the blocks of row k in order.
// No rows of A P are kept (each belongs to one aggregate), and no 3x3 products are made.
template <class Rows>
BlockSparseMatrix tentative_galerkin(const Rows& A, const FloatBlockSparseMatrix& P, const FloatBlockSparseMatrix& R) {
  tbb::enumerable_thread_specific<std::vector<std::pair<int, Matrix3>>> scratch;
  return build_block_rows(R.rows, P.cols, [&](int a, BlockRowAccumulator& row) {
    std::vector<std::pair<int, Matrix3>>& ap = scratch.local();  // row k of A P, a handful of blocks
    for (int m = R.start[static_cast<std::size_t>(a)]; m < R.start[static_cast<std::size_t>(a) + 1]; ++m) {
      const int k = R.column[static_cast<std::size_t>(m)];
      ap.clear();
      for_each_in_row(A, k, [&](int l, const Matrix3& block) {
        const int b = P.column[static_cast<std::size_t>(l)];
        const double s = P.block[static_cast<std::size_t>(l)](0, 0);
        auto it = std::find_if(ap.begin(), ap.end(), [b](const auto& entry) { return entry.first == b; });
        if (it == ap.end()) it = ap.insert(ap.end(), {b, Matrix3::Zero()});
        it->second += block * s;
      });
      const double s = R.block[static_cast<std::size_t>(m)](0, 0);
      for (const auto& [b, block] : ap) row[b] += s * block;
    }
  });
}

// The next level of a hierarchy: aggregates of A's strongly connected nodes, the smoothed and
// truncated prolongator P (rounded to float), R = P^T and the Galerkin matrix R A P of the
// rounded P; none when coarsening stalls.
struct CoarseLevel {
  std::vector<Matrix3> block_inverse;  // of A
  FloatBlockSparseMatrix P, R;
  BlockSparseMatrix A;  // R A P
};

template <class Rows>
std::optional<CoarseLevel> coarsen(const Rows& A, AdditiveMultilevel::Prolongators prolongators) {
  CoarseLevel level;
  int count = 0;
  {
    std::vector<int> start, neighbours;
    strength_graph(A, start, neighbours);
    const std::vector<int> aggregate =
        aggregate_nodes(start, neighbours, std::vector<char>(static_cast<std::size_t>(A.rows), 0), count);
    if (count == 0 || count > 0.8 * A.rows) return std::nullopt;  // coarsening stalled
    level.block_inverse = block_diagonal_inverse(A);
    if (prolongators == AdditiveMultilevel::Prolongators::Tentative) {
      level.P = tentative_prolongator(aggregate, count);
      level.R = transpose(level.P);
      level.A = tentative_galerkin(A, level.P, level.R);
      return level;
    }
    // The tentative prolongator (the translations of each aggregate) smoothed by one damped
    // block-Jacobi step, omega = 4 / (3 rho(B A)), the usual damping (it minimises the
    // prolongator's energy for the highest modes), and truncated (kProlongatorTruncation).
    const double omega = 4.0 / (3.0 * spectral_radius(level.block_inverse, A));
    level.P = rounded_to_float(
        smoothed_prolongator_of(A, aggregate, count, level.block_inverse, omega, kProlongatorTruncation));
  }
  level.R = transpose(level.P);
  level.A = galerkin_product(A, level.P, level.R);
  return level;
}

}  // namespace

AdditiveMultilevel::AdditiveMultilevel(BlockSparseMatrix A, Storage storage, int coarsest_unknowns,
                                       Prolongators prolongators) {
  if (A.rows != A.cols || A.start.size() != static_cast<std::size_t>(A.rows) + 1)
    throw std::invalid_argument("multilevel: the matrix must be square");
  auto add_level = [&](std::optional<CoarseLevel> next) {
    if (!next) return false;
    levels_.push_back(Level{std::move(next->block_inverse), std::move(next->P), std::move(next->R)});
    A = std::move(next->A);
    return true;
  };
  bool stalled = false;
  if (storage == Storage::UpperHalf) {
    // The first level from the upper half; the coarser ones, an eighth as large, whole.
    if (3 * A.rows > coarsest_unknowns) stalled = !add_level(coarsen(UpperHalf(A), prolongators));
    if (levels_.empty()) A = symmetric_from_upper(A);
  }
  while (!stalled && 3 * A.rows > coarsest_unknowns) stalled = !add_level(coarsen(A, prolongators));
  coarsest_unknowns_ = 3 * static_cast<Eigen::Index>(A.rows);
  if (coarsest_unknowns_ > std::max<Eigen::Index>(coarsest_unknowns, kLargestDenseCoarsest)) {
    // Coarsening stalled on a large level: most of its nodes have no strong neighbour (many
    // separate components, each already one node). Such a level is nearly block diagonal, so
    // its block-Jacobi inverse is nearly its inverse; a dense factor would grow as its size
    // squared in memory and cubed in time (3,000 separate spheres, 9,000 unknowns: 18 s, 650
    // MB; 30,000 would not fit in memory).
    coarsest_block_inverse_ = block_diagonal_inverse(A);
    for (const Matrix3& inverse : coarsest_block_inverse_)
      if (!inverse.allFinite() || !(inverse.trace() > 0))
        throw std::runtime_error("multilevel: the coarsest matrix is not positive definite");
    return;
  }
  Eigen::MatrixXd dense = Eigen::MatrixXd::Zero(coarsest_unknowns_, coarsest_unknowns_);
  for (int k = 0; k < A.rows; ++k)
    for (int m = A.start[static_cast<std::size_t>(k)]; m < A.start[static_cast<std::size_t>(k) + 1]; ++m)
      dense.block<3, 3>(3 * k, 3 * A.column[static_cast<std::size_t>(m)]) = A.block[static_cast<std::size_t>(m)];
  coarsest_factor_.compute(dense);
  if (coarsest_factor_.info() != Eigen::Success)
    throw std::runtime_error("multilevel: the coarsest matrix is not positive definite");
}

void AdditiveMultilevel::apply(const Eigen::VectorXd& b, Eigen::VectorXd& x) const {
  apply(0, b, x);
}

void AdditiveMultilevel::apply(std::size_t index, const Eigen::VectorXd& b, Eigen::VectorXd& x) const {
  if (index == levels_.size()) {
    if (coarsest_block_inverse_.empty()) {
      x = coarsest_factor_.solve(b);
    } else {
      x.resize(b.size());
      parallel_rows(static_cast<int>(coarsest_block_inverse_.size()), [&](int k) {
        block_at(x, k) = coarsest_block_inverse_[static_cast<std::size_t>(k)] * block_at(b, k);
      });
    }
    return;
  }
  const Level& level = levels_[index];
  Eigen::VectorXd restricted, coarse;
  level.R.multiply(b, restricted);
  apply(index + 1, restricted, coarse);
  level.P.multiply(coarse, x);
  parallel_rows(level.P.rows,
                [&](int k) { block_at(x, k) += level.block_inverse[static_cast<std::size_t>(k)] * block_at(b, k); });
}

}  // namespace vertexflow
