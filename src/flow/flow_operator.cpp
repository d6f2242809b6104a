#include "flow_operator.h"

#include "common/bucket_by_key.h"
#include "numerics/parallel.h"

#include <tbb/enumerable_thread_specific.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <memory>
#include <span>
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
template <int Size, class Scalar>
Eigen::Map<Eigen::Matrix<Scalar, Size, 1>> record(std::vector<Scalar>& data, Index i) {
  return Eigen::Map<Eigen::Matrix<Scalar, Size, 1>>(data.data() + Size * static_cast<std::size_t>(i));
}

// What vertex i contributes to the Galerkin matrix for aggregate `aggregate`.
struct Local {
  Index aggregate;
  double phi;         // phi_a(i)
  Eigen::Matrix3d g;  // (G Phi_a)_i
  double l;           // (L phi_a)_i
};

// The two one-ring passes work on four consecutive vertices at once: each vertex gathers its
// neighbours' sums as before, and the 3x3 products then run in four lanes. Each lane performs
// exactly the operations, in the same order, that the one-vertex code did (products summed left
// to right, no fused multiply-add), so the results are the same bytes on any processor; the
// kernels are compiled twice (target_clones), for AVX2 and for the baseline, and the loader
// picks one. Eigen cannot do this itself: its 3x3 products vectorise within one vertex, where
// three entries fill neither a 2- nor a 4-wide register, so the passes spent most of their
// arithmetic converting and multiplying scalars. One product H x (bench_flow's operator/
// cases) is 5-30% faster on one core; on two it is within noise. Not for memory traffic: running
// the three passes chunk by chunk, so that each reads the previous one's output from the cache,
// gained nothing either (docs/benchmarks.md, twelfth session).
constexpr Index kGroup = Sym3fGroups::kWidth;
constexpr Index kGroupsPerTask = 256;  // 1024 vertices, parallel_for_index's grain
static_assert(kVerticesPerChunk % kGroup == 0, "chunks of the sum must hold whole groups");

using Lanes = double __attribute__((vector_size(8 * kGroup)));
using FloatLanes = float __attribute__((vector_size(4 * kGroup)));

struct Vec3Lanes {
  Lanes x, y, z;
};
struct Sym3Lanes {
  Lanes xx, xy, xz, yy, yz, zz;
};

// Everything here is inlined into the two kernels, so the wide types never cross a call.
[[gnu::always_inline]] inline void widen(Lanes& out, const float (&values)[kGroup]) {
  FloatLanes f;
  std::memcpy(&f, values, sizeof f);
  out = __builtin_convertvector(f, Lanes);
}
[[gnu::always_inline]] inline void load(Sym3Lanes& m, const Sym3fGroups::Group& g) {
  widen(m.xx, g.xx), widen(m.xy, g.xy), widen(m.xz, g.xz);
  widen(m.yy, g.yy), widen(m.yz, g.yz), widen(m.zz, g.zz);
}
// Sym3f's product (block3.h), term for term.
[[gnu::always_inline]] inline void multiply(const Sym3Lanes& m, const Vec3Lanes& v, Vec3Lanes& out) {
  out.x = m.xx * v.x + m.xy * v.y + m.xz * v.z;
  out.y = m.xy * v.x + m.yy * v.y + m.yz * v.z;
  out.z = m.xz * v.x + m.yz * v.y + m.zz * v.z;
}
// v's lanes from rows staged by put (x, y, z rows of kGroup lanes each).
[[gnu::always_inline]] inline void load(Vec3Lanes& v, const double (&rows)[3][kGroup]) {
  std::memcpy(&v.x, rows[0], sizeof v.x);
  std::memcpy(&v.y, rows[1], sizeof v.y);
  std::memcpy(&v.z, rows[2], sizeof v.z);
}
[[gnu::always_inline]] inline void put(double (&rows)[3][kGroup], int lane, const Eigen::Vector3d& value) {
  rows[0][lane] = value.x(), rows[1][lane] = value.y(), rows[2][lane] = value.z();
}
template <class Scalar>
[[gnu::always_inline]] inline void store(Scalar* out, const Vec3Lanes& v, int lane) {
  out[0] = static_cast<Scalar>(v.x[lane]), out[1] = static_cast<Scalar>(v.y[lane]),
  out[2] = static_cast<Scalar>(v.z[lane]);
}

template <class Cache>
struct OperatorData {
  const FlowTerms& t;
  const double* x;  // 3 per vertex
  const Cache* kx;
  Cache* qkr;
  double* y;
};

// Group g of the second pass: q = P (G x - K sum_j x_j - sum_j K_j x_j), K q and r = S (x -
// sum_j x_j / deg - rest) into each vertex's record.
template <class Cache>
[[gnu::target_clones("avx2", "default")]] void second_pass(const OperatorData<Cache>& d, bool with_rest, Index g) {
  const FlowTerms& t = d.t;
  const Index first = kGroup * g;
  const int count = static_cast<int>(std::min<Index>(kGroup, t.n - first));
  // Lanes past the last vertex stay zero; full groups write every lane.
  double sum_x[3][kGroup], sum_kx[3][kGroup], own_x[3][kGroup], rest[3][kGroup], inv_degree[kGroup], smooth[kGroup];
  if (count < kGroup) {
    for (auto* rows : {&sum_x, &sum_kx, &own_x, &rest}) std::memset(rows, 0, sizeof *rows);
    std::memset(inv_degree, 0, sizeof inv_degree), std::memset(smooth, 0, sizeof smooth);
  }
  for (int l = 0; l < count; ++l) {
    const Index i = first + l;
    const auto [begin, end] = t.one_ring(i);
    Eigen::Vector3d sx = Eigen::Vector3d::Zero();
    Eigen::Matrix<Cache, 3, 1> skx = Eigen::Matrix<Cache, 3, 1>::Zero();  // summed as stored
    for (const Index* j = begin; j != end; ++j) {
      sx += Eigen::Map<const Eigen::Vector3d>(d.x + 3 * static_cast<std::ptrdiff_t>(*j));
      skx += Eigen::Map<const Eigen::Matrix<Cache, 3, 1>>(d.kx + 3 * static_cast<std::ptrdiff_t>(*j));
    }
    put(sum_x, l, sx);
    put(sum_kx, l, skx.template cast<double>());
    put(own_x, l, Eigen::Map<const Eigen::Vector3d>(d.x + 3 * static_cast<std::ptrdiff_t>(i)));
    if (with_rest) put(rest, l, t.rest[static_cast<std::size_t>(i)]);
    inv_degree[l] = t.inv_degree[static_cast<std::size_t>(i)];
    smooth[l] = t.smooth[static_cast<std::size_t>(i)];
  }
  Sym3Lanes G, K, P;
  const auto group = static_cast<std::size_t>(g);
  load(G, t.G.group(group)), load(K, t.K.group(group)), load(P, t.P.group(group));
  Vec3Lanes sx, skx, xi, a, b;
  load(sx, sum_x), load(skx, sum_kx), load(xi, own_x);
  multiply(G, xi, a);
  multiply(K, sx, b);
  Vec3Lanes u{a.x - b.x - skx.x, a.y - b.y - skx.y, a.z - b.z - skx.z};
  Vec3Lanes q, kq;
  multiply(P, u, q);
  multiply(K, q, kq);
  Lanes s, w;
  std::memcpy(&s, inv_degree, sizeof s);
  std::memcpy(&w, smooth, sizeof w);
  Vec3Lanes laplacian{xi.x - s * sx.x, xi.y - s * sx.y, xi.z - s * sx.z};
  if (with_rest) {
    Vec3Lanes r0;
    load(r0, rest);
    laplacian.x -= r0.x, laplacian.y -= r0.y, laplacian.z -= r0.z;
  }
  const Vec3Lanes r{w * laplacian.x, w * laplacian.y, w * laplacian.z};
  // The record holds r / deg, the term of r in the rows of i's neighbours, and y holds r until the
  // third pass reads it there and writes y: no 1 / deg(j) to gather per neighbour.
  const Vec3Lanes r_by_degree{s * r.x, s * r.y, s * r.z};
  for (int l = 0; l < count; ++l) {
    Cache* out = d.qkr + 9 * static_cast<std::ptrdiff_t>(first + l);
    store(out, q, l), store(out + 3, kq, l), store(out + 6, r_by_degree, l);
    store(d.y + 3 * static_cast<std::ptrdiff_t>(first + l), r, l);
  }
}

// Groups [g0, g1) of the third pass: y = G q - K sum_j q_j - sum_j K_j q_j + r - sum_j r_j /
// deg(j) (+ D x), zero at fixed vertices; returns the sum of x . y over the groups' vertices, in
// order.
template <class Cache>
[[gnu::target_clones("avx2", "default")]] double third_pass(const OperatorData<Cache>& d, bool with_d, Index g0,
                                                            Index g1) {
  const FlowTerms& t = d.t;
  double total = 0;
  for (Index g = g0; g < g1; ++g) {
    const Index first = kGroup * g;
    const int count = static_cast<int>(std::min<Index>(kGroup, t.n - first));
    double sum_q[3][kGroup], sum_kq[3][kGroup], sum_r[3][kGroup], own_q[3][kGroup], own_r[3][kGroup], own_x[3][kGroup];
    if (count < kGroup)
      for (auto* rows : {&sum_q, &sum_kq, &sum_r, &own_q, &own_r, &own_x}) std::memset(rows, 0, sizeof *rows);
    for (int l = 0; l < count; ++l) {
      const Index u = first + l;
      const auto [begin, end] = t.one_ring(u);
      Eigen::Matrix<Cache, 9, 1> records = Eigen::Matrix<Cache, 9, 1>::Zero();  // summed as stored
      for (const Index* j = begin; j != end; ++j)
        records += Eigen::Map<const Eigen::Matrix<Cache, 9, 1>>(d.qkr + 9 * static_cast<std::ptrdiff_t>(*j));
      const Eigen::Matrix<double, 9, 1> sum = records.template cast<double>();
      put(sum_q, l, sum.head<3>());
      put(sum_kq, l, sum.segment<3>(3));
      put(sum_r, l, sum.tail<3>());
      put(own_q, l,
          Eigen::Map<const Eigen::Matrix<Cache, 3, 1>>(d.qkr + 9 * static_cast<std::ptrdiff_t>(u))
              .template cast<double>());
      put(own_r, l, Eigen::Map<const Eigen::Vector3d>(d.y + 3 * static_cast<std::ptrdiff_t>(u)));
      put(own_x, l, Eigen::Map<const Eigen::Vector3d>(d.x + 3 * static_cast<std::ptrdiff_t>(u)));
    }
    Sym3Lanes G, K;
    const auto group = static_cast<std::size_t>(g);
    load(G, t.G.group(group)), load(K, t.K.group(group));
    Vec3Lanes sq, skq, sr, qu, ru, xu, a, b;
    load(sq, sum_q), load(skq, sum_kq), load(sr, sum_r), load(qu, own_q), load(ru, own_r), load(xu, own_x);
    multiply(G, qu, a);
    multiply(K, sq, b);
    Vec3Lanes out{a.x - b.x - skq.x + ru.x - sr.x, a.y - b.y - skq.y + ru.y - sr.y, a.z - b.z - skq.z + ru.z - sr.z};
    if (with_d) {
      Sym3Lanes D;
      load(D, t.D.group(group));
      Vec3Lanes dx;
      multiply(D, xu, dx);
      out.x += dx.x, out.y += dx.y, out.z += dx.z;
    }
    const Lanes dot = xu.x * out.x + xu.y * out.y + xu.z * out.z;
    for (int l = 0; l < count; ++l) {
      double* y = d.y + 3 * static_cast<std::ptrdiff_t>(first + l);
      if (t.fixed[static_cast<std::size_t>(first + l)]) {
        y[0] = y[1] = y[2] = 0;
        total += 0.0;  // the one-vertex code added a fixed vertex's 0 too (it turns a -0 sum into +0)
      } else {
        store(y, out, l);
        total += dot[l];
      }
    }
  }
  return total;
}

}  // namespace

FlowOperator::FlowOperator(const FlowTerms& terms, CachePrecision precision) : t_(terms), precision_(precision) {}

void FlowOperator::use_cache_precision(CachePrecision precision) {
  if (precision == precision_) return;
  release_caches();
  precision_ = precision;
}

void FlowOperator::release_caches() {
  std::vector<float>().swap(kx_float_);
  std::vector<float>().swap(qkr_float_);
  std::vector<double>().swap(kx_double_);
  std::vector<double>().swap(qkr_double_);
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
  return precision_ == CachePrecision::Float
             ? passes(kx_float_, qkr_float_, x, y, with_d, with_rest, std::forward<First>(first))
             : passes(kx_double_, qkr_double_, x, y, with_d, with_rest, std::forward<First>(first));
}

template <class Cache, class First>
double FlowOperator::passes(std::vector<Cache>& kx, std::vector<Cache>& qkr, const BlockVector& x, BlockVector& y,
                            bool with_d, bool with_rest, First&& first) {
  const auto n = static_cast<std::size_t>(t_.n);
  if (kx.size() != 3 * n) kx.resize(3 * n);
  if (qkr.size() != 9 * n) qkr.resize(9 * n);
  parallel_for_index(t_.n, [&](Index i) {
    const Eigen::Vector3d xi = first(i);
    record<3>(kx, i) = (t_.K[static_cast<std::size_t>(i)] * xi).template cast<Cache>();
  });
  const OperatorData<Cache> data{t_, x.data(), kx.data(), qkr.data(), y.data()};
  const Index groups = (t_.n + kGroup - 1) / kGroup;
  parallel_for_index(
      groups, [&](Index g) { second_pass(data, with_rest, g); }, kGroupsPerTask);
  // y = G q + L^T r (+ D x), G symmetric; x . y summed per vertex in order.
  return deterministic_sum(t_.n, kVerticesPerChunk, 0.0, [&](std::ptrdiff_t begin, std::ptrdiff_t end) {
    return third_pass(data, with_d, static_cast<Index>(begin / kGroup),
                      static_cast<Index>((end + kGroup - 1) / kGroup));
  });
}

BlockSparseMatrix galerkin_upper(const FlowTerms& t, const AggregationCoarseSpace& space) {
  const auto n = static_cast<std::size_t>(t.n);
  const auto na = static_cast<std::size_t>(space.size());
  // The rows are built for a range of aggregates at a time, from the locals (below) of the
  // vertices that touch it only: the locals of all vertices at once (96 bytes each, about 5.6
  // per vertex) were the flow's peak memory on large meshes (540 of 2,129 bytes per vertex at
  // 2.8M vertices, docs/benchmarks.md). Vertices and aggregates are numbered along the surface,
  // so a range's vertices are about its share; a vertex on a range's edge computes its locals
  // twice. Each block is still summed over the vertices in order, so the matrix does not depend
  // on the ranges. 64 rather than 32: build_block_rows holds a range's rows twice while it
  // copies them into place, which raised the 10M peak by about 100 MB (docs/benchmarks.md).
  constexpr std::size_t kRanges = 64, kMinRange = 4096;
  static_assert(kRanges <= 256, "range numbers are stored in a byte");
  const std::size_t range = std::max(kMinRange, (na + kRanges - 1) / kRanges);
  // Per vertex i (the rows of A at i, fixed vertices included): for each aggregate a whose
  // basis function is non-zero on the star of i, phi_a(i), the 3x3 block (G Phi_a)_i and the
  // entry (L phi_a)_i: its "locals". First their number and the ranges of their aggregates.
  std::vector<std::uint32_t> local_size(n, 0);
  std::vector<std::uint8_t> first_range(n, 0), last_range(n, 0);
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
    if (aggregates.empty()) return;
    const auto [lowest, highest] = std::minmax_element(aggregates.begin(), aggregates.end());
    first_range[v] = static_cast<std::uint8_t>(static_cast<std::size_t>(*lowest) / range);
    last_range[v] = static_cast<std::uint8_t>(static_cast<std::size_t>(*highest) / range);
  });
  // The vertices that touch each range, in vertex order: found once, where scanning every
  // vertex for every range was a serial pass per range (about 2 s at 10M vertices).
  const std::size_t ranges = (na + range - 1) / range;
  KeyBuckets<Index, std::uint32_t> range_vertices = bucket_by_key<Index, std::uint32_t>(ranges, [&](auto&& emit) {
    for (std::size_t i = 0; i < n; ++i)
      if (local_size[i] > 0)
        for (std::size_t r = first_range[i]; r <= last_range[i]; ++r) emit(r, static_cast<Index>(i));
  });
  std::vector<std::uint8_t>().swap(first_range);
  std::vector<std::uint8_t>().swap(last_range);

  std::span<const Index> vertices;
  std::vector<std::size_t> local_start;
  // The range's locals; not initialised (every one is written below), and kept between ranges.
  std::unique_ptr<Local[]> locals;
  std::size_t locals_capacity = 0;
  // Their aggregates again, packed: the counting sort below reads 4 bytes per local instead of
  // a local's cache line (at 10M vertices its two passes took 0.7 s, from the locals).
  std::vector<Index> local_aggregate;
  std::size_t first = 0;                                        // the range's first aggregate
  KeyBuckets<std::pair<std::uint32_t, std::uint32_t>> touches;  // per aggregate of the range: (vertex in range, k)
  auto prepare = [&](int range_first, int range_last) {
    const auto a0 = static_cast<std::size_t>(range_first), a1 = static_cast<std::size_t>(range_last);
    first = a0;
    vertices = range_vertices.of(a0 / range);
    const std::size_t m = vertices.size();
    local_start.assign(m + 1, 0);
    for (std::size_t c = 0; c < m; ++c)
      local_start[c + 1] = local_start[c] + local_size[static_cast<std::size_t>(vertices[c])];
    if (local_start[m] > locals_capacity) {
      locals.reset();
      locals_capacity = local_start[m] + local_start[m] / 8;
      locals.reset(new Local[locals_capacity]);
    }
    local_aggregate.resize(local_start[m]);
    parallel_for_index(static_cast<Index>(m), [&](Index c) {
      const Index i = vertices[static_cast<std::size_t>(c)];
      const auto v = static_cast<std::size_t>(i);
      Local* out = locals.get() + local_start[static_cast<std::size_t>(c)];
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
      for (std::uint32_t k = 0; k < size; ++k)
        local_aggregate[local_start[static_cast<std::size_t>(c)] + k] = out[k].aggregate;
    });
    // The locals of each aggregate of the range, by vertex (a counting sort, so in vertex
    // order; in fixed chunks of the vertices, counted and placed on all threads).
    constexpr std::size_t kChunks = 8;
    touches = bucket_by_key_in_chunks<std::pair<std::uint32_t, std::uint32_t>>(
        a1 - a0, kChunks, [&](std::size_t part, auto&& emit) {
          const auto [begin, end] = chunk_range(m, kChunks, part);
          for (std::size_t c = begin; c < end; ++c)
            for (std::size_t k = local_start[c]; k < local_start[c + 1]; ++k) {
              const auto a = static_cast<std::size_t>(local_aggregate[k]);
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
          const Local* local = locals.get() + local_start[c];
          const Local& x = local[k];
          const Eigen::Matrix3d left = x.g * t.P[v].full();
          const Eigen::Matrix3d D = t.D[v].full();             // phi is 0 at fixed vertices, so their D drops out
          for (std::uint32_t q = k; q < local_size[v]; ++q) {  // sorted, so local[q].aggregate >= a
            const Local& y = local[q];
            Eigen::Matrix3d& block = row[y.aggregate];
            block.noalias() += left * y.g;
            block.diagonal().array() += t.smooth[v] * x.l * y.l;
            if (x.phi != 0 && y.phi != 0) block.noalias() += (x.phi * y.phi) * D;  // else a zero block: skipped
          }
        }
      },
      static_cast<int>(range), prepare);
}

}  // namespace vertexflow
