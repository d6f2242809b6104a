#include "flow_operator.h"

#include "common/bucket_by_key.h"
#include "numerics/parallel.h"

#include <tbb/enumerable_thread_specific.h>

#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

namespace vertexflow {
namespace {

// What a vertex reads of its neighbours is interleaved in one record per vertex, so that a
// neighbour costs one or two cache lines instead of one per array: the gathers' cache misses
// were the hot spots of both one-ring passes. The first pass's record no longer copies x beside
// K x: x is read where it lies (the vertices are numbered along the surface, so a one-ring's x
// share cache lines), 24 bytes per vertex fewer and, on one core at 1M vertices, a tenth less
// solve time (writing the copy cost more than the second gather).
template <int Size>
Eigen::Map<Eigen::Matrix<double, Size, 1>> record(std::vector<double>& data, Index i) {
  return Eigen::Map<Eigen::Matrix<double, Size, 1>>(data.data() + Size * static_cast<std::size_t>(i));
}

// What vertex i contributes to the Galerkin matrix for aggregate `aggregate`.
struct Local {
  Index aggregate;
  double phi;         // phi_a(i)
  Eigen::Matrix3d g;  // (G Phi_a)_i
  double l;           // (L phi_a)_i
};

}  // namespace

FlowOperator::FlowOperator(const FlowTerms& terms) : t_(terms) {}

void FlowOperator::release_caches() {
  std::vector<double>().swap(kx_);
  std::vector<double>().swap(qkr_);
}

double FlowOperator::apply(const BlockVector& x, BlockVector& y) {
  return passes(x, y, true, false, [&](Index i) -> Eigen::Vector3d { return block_at(x, i); });
}

double FlowOperator::apply_updated(BlockVector& p, const PreconditionedResidual& z, double beta, BlockVector& y) {
  return passes(p, y, true, false, [&](Index i) -> Eigen::Vector3d {
    const Eigen::Vector3d updated = z(i) + beta * block_at(p, i);
    block_at(p, i) = updated;
    return updated;
  });
}

BlockVector FlowOperator::right_hand_side(const BlockVector& x) {
  BlockVector b(x.size());
  passes(x, b, false, true, [&](Index i) -> Eigen::Vector3d { return block_at(x, i); });
  b = -b;
  return b;
}

// first(i) gives x_i (and may write it) in the first pass; the later passes read x.
template <class First>
double FlowOperator::passes(const BlockVector& x, BlockVector& y, bool with_d, bool with_rest, First&& first) {
  const auto n = static_cast<std::size_t>(t_.n);
  if (kx_.size() != 3 * n) kx_.resize(3 * n);
  if (qkr_.size() != 9 * n) qkr_.resize(9 * n);
  parallel_for_index(t_.n, [&](Index i) {
    const Eigen::Vector3d xi = first(i);
    record<3>(kx_, i) = t_.K[static_cast<std::size_t>(i)] * xi;
  });
  parallel_for_index(t_.n, [&](Index i) {
    const auto v = static_cast<std::size_t>(i);
    const auto [begin, end] = t_.one_ring(i);
    Eigen::Vector3d sum_x = Eigen::Vector3d::Zero(), sum_kx = Eigen::Vector3d::Zero();
    for (const Index* j = begin; j != end; ++j) {
      sum_x += block_at(x, *j);
      sum_kx += record<3>(kx_, *j);
    }
    const Eigen::Vector3d xi = block_at(x, i);
    const Eigen::Vector3d q = t_.P[v] * Eigen::Vector3d(t_.G[v] * xi - t_.K[v] * sum_x - sum_kx);
    Eigen::Vector3d laplacian = xi - t_.inv_degree[v] * sum_x;
    if (with_rest) laplacian -= t_.rest[v];
    const Eigen::Vector3d r = t_.smooth[v] * laplacian;
    auto out = record<9>(qkr_, i);
    out.head<3>() = q;
    out.segment<3>(3) = t_.K[v] * q;
    out.tail<3>() = r;
  });
  // y = G q + L^T r (+ D x), G symmetric.
  return sum_over_vertices(t_.n, 0.0, [&](Index u) {
    const auto v = static_cast<std::size_t>(u);
    if (t_.fixed[v]) {
      block_at(y, u).setZero();
      return 0.0;
    }
    const auto [begin, end] = t_.one_ring(u);
    // r_j / deg(j) is formed here rather than stored: the same products, so the same bytes,
    // and r_u comes from the record instead of a vector of its own (24 bytes per vertex).
    Eigen::Matrix<double, 6, 1> sum = Eigen::Matrix<double, 6, 1>::Zero();
    Eigen::Vector3d sum_r = Eigen::Vector3d::Zero();
    for (const Index* j = begin; j != end; ++j) {
      const auto neighbour = record<9>(qkr_, *j);
      sum += neighbour.head<6>();
      sum_r += t_.inv_degree[static_cast<std::size_t>(*j)] * neighbour.tail<3>();
    }
    const auto own = record<9>(qkr_, u);
    const Eigen::Vector3d xu = block_at(x, u), qu = own.head<3>();
    Eigen::Vector3d out =
        t_.G[v] * qu - t_.K[v] * Eigen::Vector3d(sum.head<3>()) - sum.segment<3>(3) + own.tail<3>() - sum_r;
    if (with_d) out += t_.D[v] * xu;
    block_at(y, u) = out;
    return xu.dot(out);
  });
}

BlockSparseMatrix galerkin_upper(const FlowTerms& t, const AggregationCoarseSpace& space) {
  const auto n = static_cast<std::size_t>(t.n);
  const auto na = static_cast<std::size_t>(space.size());
  // Per vertex i (the rows of A at i, fixed vertices included): for each aggregate a whose
  // basis function is non-zero on the star of i, phi_a(i), the 3x3 block (G Phi_a)_i and the
  // entry (L phi_a)_i: its "locals". First their number and the range of their aggregates.
  std::vector<std::uint32_t> local_size(n, 0);
  std::vector<Index> lowest(n, static_cast<Index>(na)), highest(n, -1);
  tbb::enumerable_thread_specific<std::vector<Index>> seen;
  parallel_for_index(t.n, [&](Index i) {
    std::vector<Index>& aggregates = seen.local();  // distinct, a handful: linear search
    aggregates.clear();
    t.for_each_in_star(i, [&](Index u) {
      for (const AggregationCoarseSpace::Weight& w : space.basis(u))
        if (std::find(aggregates.begin(), aggregates.end(), w.aggregate) == aggregates.end())
          aggregates.push_back(w.aggregate);
    });
    const auto v = static_cast<std::size_t>(i);
    local_size[v] = static_cast<std::uint32_t>(aggregates.size());
    for (const Index a : aggregates) {
      lowest[v] = std::min(lowest[v], a);
      highest[v] = std::max(highest[v], a);
    }
  });

  // The rows are built for a range of aggregates at a time, from the locals of the vertices that
  // touch it only: the locals of all vertices at once (96 bytes each, about 5.6 per vertex) were
  // the flow's peak memory on large meshes (540 of 2,129 bytes per vertex at 2.8M vertices,
  // docs/benchmarks.md). Vertices and aggregates are numbered along the surface, so a range's
  // vertices are about its share; a vertex on a range's edge computes its locals twice. Each
  // block is still summed over the vertices in order, so the matrix does not depend on the
  // ranges.
  constexpr std::size_t kRanges = 32, kMinRange = 4096;
  const std::size_t range = std::max(kMinRange, (na + kRanges - 1) / kRanges);
  std::vector<Index> vertices;
  std::vector<std::size_t> local_start;
  std::vector<Local> locals;
  std::size_t first = 0;                                        // the range's first aggregate
  KeyBuckets<std::pair<std::uint32_t, std::uint32_t>> touches;  // per aggregate of the range: (vertex in range, k)
  auto prepare = [&](int range_first, int range_last) {
    const auto a0 = static_cast<std::size_t>(range_first), a1 = static_cast<std::size_t>(range_last);
    first = a0;
    vertices.clear();
    for (std::size_t i = 0; i < n; ++i)
      if (local_size[i] > 0 && static_cast<std::size_t>(lowest[i]) < a1 && static_cast<std::size_t>(highest[i]) >= a0)
        vertices.push_back(static_cast<Index>(i));
    const std::size_t m = vertices.size();
    local_start.assign(m + 1, 0);
    for (std::size_t c = 0; c < m; ++c)
      local_start[c + 1] = local_start[c] + local_size[static_cast<std::size_t>(vertices[c])];
    locals.assign(local_start[m], Local{});
    parallel_for_index(static_cast<Index>(m), [&](Index c) {
      const Index i = vertices[static_cast<std::size_t>(c)];
      const auto v = static_cast<std::size_t>(i);
      Local* out = locals.data() + local_start[static_cast<std::size_t>(c)];
      std::uint32_t size = 0;
      auto find = [&](Index a) -> Local& {
        for (std::uint32_t k = 0; k < size; ++k)
          if (out[k].aggregate == a) return out[k];
        out[size] = Local{a, 0, Eigen::Matrix3d::Zero(), 0};
        return out[size++];
      };
      const Eigen::Matrix3d G = t.G[v].full(), K = t.K[v].full();
      for (const AggregationCoarseSpace::Weight& w : space.basis(i)) {
        Local& x = find(w.aggregate);
        x.phi = w.value;
        x.g += w.value * G;
        x.l += w.value;
      }
      const auto [begin, end] = t.one_ring(i);
      for (const Index* j = begin; j != end; ++j) {
        const Eigen::Matrix3d coupling = K + t.K[static_cast<std::size_t>(*j)].full();
        for (const AggregationCoarseSpace::Weight& w : space.basis(*j)) {
          Local& x = find(w.aggregate);
          x.g -= w.value * coupling;
          x.l -= t.inv_degree[v] * w.value;
        }
      }
      std::sort(out, out + size, [](const Local& x, const Local& y) { return x.aggregate < y.aggregate; });
    });
    // The locals of each aggregate of the range, by vertex (counting sort, so in vertex order).
    touches = bucket_by_key<std::pair<std::uint32_t, std::uint32_t>>(a1 - a0, [&](auto&& emit) {
      for (std::size_t c = 0; c < m; ++c)
        for (std::size_t k = local_start[c]; k < local_start[c + 1]; ++k) {
          const auto a = static_cast<std::size_t>(locals[k].aggregate);
          if (a >= a0 && a < a1)
            emit(a - a0, std::pair{static_cast<std::uint32_t>(c), static_cast<std::uint32_t>(k - local_start[c])});
        }
    });
  };
  // Row a of the upper half of H_c: blocks (a, b), b >= a, summed over the vertices in order.
  return build_block_rows(
      static_cast<int>(na), static_cast<int>(na),
      [&](int a, BlockRowAccumulator& row) {
        const std::size_t r = static_cast<std::size_t>(a) - first;
        for (const auto& [c, k] : touches.of(r)) {
          const auto v = static_cast<std::size_t>(vertices[c]);
          const Local* local = locals.data() + local_start[c];
          const Local& x = local[k];
          const Eigen::Matrix3d left = x.g * t.P[v].full();
          const Eigen::Matrix3d D = t.D[v].full();             // phi is 0 at fixed vertices, so their D drops out
          for (std::uint32_t q = k; q < local_size[v]; ++q) {  // sorted, so local[q].aggregate >= a
            const Local& y = local[q];
            Eigen::Matrix3d& block = row[y.aggregate];
            block.noalias() += left * y.g;
            block.diagonal().array() += t.smooth[v] * x.l * y.l;
            block.noalias() += (x.phi * y.phi) * D;
          }
        }
      },
      static_cast<int>(range), prepare);
}

}  // namespace vertexflow
