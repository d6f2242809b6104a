#include "normal_matrix.h"

#include "numerics/parallel.h"

#include <tbb/enumerable_thread_specific.h>

#include <algorithm>
#include <span>

namespace vertexflow {

NormalMatrixPattern normal_matrix_pattern(const FlowTerms& t) {
  NormalMatrixPattern pattern;
  std::vector<Index>& free_index = pattern.free_index;
  std::vector<Index>& free_vertex = pattern.free_vertex;
  free_index.assign(static_cast<std::size_t>(t.n), -1);
  for (Index k = 0; k < t.n; ++k) {
    if (t.fixed[static_cast<std::size_t>(k)]) continue;
    free_index[static_cast<std::size_t>(k)] = static_cast<Index>(free_vertex.size());
    free_vertex.push_back(k);
  }
  const auto m = static_cast<Index>(free_vertex.size()), n = t.n;
  std::vector<std::int64_t>& row_start = pattern.row_start;
  std::vector<Index>& row_columns = pattern.row_columns;
  std::vector<std::vector<Index>> rows(static_cast<std::size_t>(m));
  tbb::enumerable_thread_specific<std::vector<Index>> marks(
      [n] { return std::vector<Index>(static_cast<std::size_t>(n), -1); });
  parallel_for_index(m, [&](Index a) {
    std::vector<Index>& mark = marks.local();
    std::vector<Index>& row = rows[static_cast<std::size_t>(a)];
    const Index u = free_vertex[static_cast<std::size_t>(a)];
    auto visit = [&](Index w) {
      const Index b = free_index[static_cast<std::size_t>(w)];
      if (b < 0 || b > a || mark[static_cast<std::size_t>(w)] == a) return;
      mark[static_cast<std::size_t>(w)] = a;
      row.push_back(b);
    };
    t.for_each_in_star(u, [&](Index i) { t.for_each_in_star(i, visit); });
    std::sort(row.begin(), row.end());
  });
  row_start.assign(static_cast<std::size_t>(m) + 1, 0);
  for (Index a = 0; a < m; ++a)
    row_start[static_cast<std::size_t>(a) + 1] =
        row_start[static_cast<std::size_t>(a)] + static_cast<std::int64_t>(rows[static_cast<std::size_t>(a)].size());
  row_columns.resize(static_cast<std::size_t>(row_start.back()));
  parallel_for_index(m, [&](Index a) {
    const auto& row = rows[static_cast<std::size_t>(a)];
    std::copy(row.begin(), row.end(), row_columns.begin() + row_start[static_cast<std::size_t>(a)]);
  });
  return pattern;
}

SparseCholesky::UpperMatrix assemble_normal_matrix(const FlowTerms& t, const NormalMatrixPattern& pattern,
                                                   SparseCholesky& cholesky) {
  const std::vector<Index>& free_vertex = pattern.free_vertex;
  const std::vector<std::int64_t>& row_start = pattern.row_start;
  const std::vector<Index>& row_columns = pattern.row_columns;
  const auto m = static_cast<Index>(free_vertex.size()), n = t.n;
  std::vector<std::int64_t> column_start(3 * static_cast<std::size_t>(m) + 1, 0);
  for (Index a = 0; a < m; ++a) {
    const auto off_diagonal =
        3 * (row_start[static_cast<std::size_t>(a) + 1] - row_start[static_cast<std::size_t>(a)] - 1);
    for (int r = 0; r < 3; ++r) {
      const std::size_t column = 3 * static_cast<std::size_t>(a) + static_cast<std::size_t>(r);
      column_start[column + 1] = column_start[column] + off_diagonal + r + 1;
    }
  }
  SparseCholesky::UpperMatrix A = cholesky.allocate_upper(column_start);
  const std::span<std::int64_t> rows = A.rows();
  const std::span<double> values = A.values();
  tbb::enumerable_thread_specific<std::vector<std::int64_t>> positions(
      [n] { return std::vector<std::int64_t>(static_cast<std::size_t>(n), -1); });
  tbb::enumerable_thread_specific<std::vector<Eigen::Matrix3d>> scratch;
  parallel_for_index(m, [&](Index a) {
    std::vector<std::int64_t>& position = positions.local();
    std::vector<Eigen::Matrix3d>& blocks = scratch.local();
    const auto first = row_start[static_cast<std::size_t>(a)], last = row_start[static_cast<std::size_t>(a) + 1];
    blocks.assign(static_cast<std::size_t>(last - first), Eigen::Matrix3d::Zero());
    for (auto k = first; k < last; ++k)
      position[static_cast<std::size_t>(
          free_vertex[static_cast<std::size_t>(row_columns[static_cast<std::size_t>(k)])])] = k - first;
    const Index u = free_vertex[static_cast<std::size_t>(a)];
    // Block (u, w) = sum over i whose star holds u and w of G_iu P_i G_iw + S_i L_iu L_iw I.
    auto add_star = [&](Index i) {
      const Eigen::Matrix3d left = t.g_block(i, u) * t.P[static_cast<std::size_t>(i)].full();
      const double l_u = t.smooth[static_cast<std::size_t>(i)] * t.l_entry(i, u);
      auto add = [&](Index w) {
        const std::int64_t k = position[static_cast<std::size_t>(w)];
        if (k < 0) return;  // fixed, or w > u
        Eigen::Matrix3d& block = blocks[static_cast<std::size_t>(k)];
        block.noalias() += left * t.g_block(i, w);
        block.diagonal().array() += l_u * t.l_entry(i, w);
      };
      t.for_each_in_star(i, add);
    };
    t.for_each_in_star(u, add_star);
    blocks.back() += t.D[static_cast<std::size_t>(u)].full();
    for (auto k = first; k < last; ++k)
      position[static_cast<std::size_t>(
          free_vertex[static_cast<std::size_t>(row_columns[static_cast<std::size_t>(k)])])] = -1;
    // Scatter: entry (3b + c, 3a + r) is H_{ur, wc} = block(u, w)(r, c).
    for (int r = 0; r < 3; ++r) {
      auto out = column_start[3 * static_cast<std::size_t>(a) + static_cast<std::size_t>(r)];
      for (auto k = first; k < last; ++k) {
        const Index b = row_columns[static_cast<std::size_t>(k)];
        const int columns = b == a ? r + 1 : 3;
        for (int c = 0; c < columns; ++c) {
          rows[static_cast<std::size_t>(out)] = 3 * static_cast<std::int64_t>(b) + c;
          values[static_cast<std::size_t>(out)] = blocks[static_cast<std::size_t>(k - first)](r, c);
          ++out;
        }
      }
    }
  });
  return A;
}

}  // namespace vertexflow
