// Solves the flow's normal equations H d = b (flow_solver.h) by one of three methods.
//
// H = A^T A of flow_energy.h's rows is a sum of one-ring products. With K_i the curvature
// tensor, G the 3n x 3n block operator (G x)_i = sum_{j in N(i)} (K_i + K_j)(x_i - x_j) (the g_i
// of Eq. 16; symmetric), P_i = 1/|E| (T_i1 T_i1^T + T_i2 T_i2^T) the weighted tangent projector,
// L the uniform Laplacian of Eq. 8, S = diag(mu mu_i / |V|) and D_i the 3x3 block of F_sd and
// the pull:
//   H = G P G + (L^T S L) (x) I_3 + D,     b = -(G P G P + L^T S (L P - R)),
// R the fairness targets. So H x costs two passes over the one-rings (no matrix), and any
// block of H is a short sum over the vertices whose one-rings contain both of its vertices.
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
//   (MultilevelCorrection below, multigrid.h): smoothed aggregates of one-rings whose Galerkin
//   matrix is coarsened again. It is for the smooth tangential modes of large flat regions.
//
// Why these two and how the choice is made (measured on this project's meshes, docs/benchmarks.md):
// the coupled factorisation costs about n^1.5 (3.1e9 flops at 9k vertices, 1.8e10 at 43k, an
// estimated 2e12 and 16 GB at 1M), the iteration costs about n, and the iteration count stays
// between 80 and 300 on smooth meshes of any size at the default tolerance 1e-7 (bunny 9k: 80,
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

#include "multigrid.h"

#include "vertexflow/timing.h"

#include <cholmod.h>
#include <sys/resource.h>
#include <dlfcn.h>
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#include <numeric>
#include <optional>
#include <span>
#include <new>
#include <stdexcept>

namespace vertexflow {
namespace {

using Matrix3 = Eigen::Matrix3d;
using Vector3 = Eigen::Vector3d;
using Vector = Eigen::VectorXd;  // 3 entries per vertex, x0 y0 z0 x1 ... (Vertices' layout)

// A symmetric 3x3 matrix stored as its upper triangle: the per-vertex factors of H are all
// symmetric, and the iteration is bound by memory traffic, so 48 bytes instead of 72 matter.
struct Sym3 {
  double xx = 0, xy = 0, xz = 0, yy = 0, yz = 0, zz = 0;

  Sym3() = default;
  explicit Sym3(const Matrix3& m) : xx(m(0, 0)), xy(m(0, 1)), xz(m(0, 2)), yy(m(1, 1)), yz(m(1, 2)), zz(m(2, 2)) {}
  [[nodiscard]] Matrix3 full() const {
    Matrix3 m;
    m << xx, xy, xz, xy, yy, yz, xz, yz, zz;
    return m;
  }
  [[nodiscard]] Vector3 operator*(const Vector3& v) const {
    return {xx * v.x() + xy * v.y() + xz * v.z(), xy * v.x() + yy * v.y() + yz * v.z(),
            xz * v.x() + yz * v.y() + zz * v.z()};
  }
};

// Free vertices at or below this count are factored directly: a few milliseconds, exact, and
// no iteration count to depend on (sphere_low, 589 vertices: 20 ms CPU direct, 1 ms iterating).
constexpr Index kDirectBelow = 1000;
// Iterations allowed before the fallback to the factorisation: the factorisation's time over
// one iteration's time, both measured on bunny_uniform, armadillo-43k and amo (time ~ 4.5e-7
// n^1.5 s against ~2.5e-8 n s on 2 cores, so the ratio is about 18 sqrt(n)).
constexpr double kBudgetPerSqrtVertex = 18.0;
// LinearSolver::Automatic takes the multilevel preconditioner when a connected region of at
// least kFlatRegionForMultilevel free vertices has |k1| + |k2| < kFlatCurvature (per mean edge
// length): there F_em vanishes and block-Jacobi's iteration count grows like the region's
// diameter squared. Measured (largest such region; block-Jacobi against multilevel
// iterations): fandisk 1,257 vertices, 930 against 114; amo 4,825, 291 against 97; every other
// data mesh at most 105 vertices. Starting multilevel at once saves the probe below.
constexpr double kFlatCurvature = 0.01;
constexpr Index kFlatRegionForMultilevel = 500;
// Otherwise block-Jacobi runs kProbeIterations, and if the Lanczos estimate of its total
// (ConjugateGradients::predicted_iterations, a lower bound) is above kSwitchAbovePredicted the
// iteration continues with the multilevel preconditioner. The set-up costs about 30-50
// block-Jacobi iterations, and the multilevel count is 40-70% of block-Jacobi's, so it pays from
// about 120 remaining iterations. Measured after 30 iterations (estimate; actual count):
// bunny_uniform 67; 79, horse-48k 89; 93, rocker-arm 91; 90, armadillo-43k 95; 129 stay;
// max-planck-5k 111; 146, fertility 113; 140, spot 121; 222, camelhead 149; 568 switch.
constexpr int kProbeIterations = 30;
constexpr double kSwitchAbovePredicted = 105;
// Without a fallback (the factorisation would not fit) the iteration stops at this many
// times the budget.
constexpr int kIterationCapFactor = 10;
// The fallback is taken only when the predicted factor (9 x the vertex graph's fill) fits.
constexpr double kMaxFactorBytes = 2.0 * 1024 * 1024 * 1024;

template <class Body>
void parallel_vertices(Index n, Body&& body) {
  tbb::parallel_for(tbb::blocked_range<Index>(0, n, 1024), [&](const tbb::blocked_range<Index>& range) {
    for (Index i = range.begin(); i != range.end(); ++i) body(i);
  });
}

Eigen::Map<Vector3> at(Vector& v, Index i) {
  return Eigen::Map<Vector3>(v.data() + 3 * static_cast<Eigen::Index>(i));
}
Eigen::Map<const Vector3> at(const Vector& v, Index i) {
  return Eigen::Map<const Vector3>(v.data() + 3 * static_cast<Eigen::Index>(i));
}

// Dot product summed in fixed chunks, so that its rounding does not depend on the threads.
double dot(const Vector& a, const Vector& b) {
  constexpr Eigen::Index kChunk = 8192;
  const Eigen::Index chunks = (a.size() + kChunk - 1) / kChunk;
  std::vector<double> partial(static_cast<std::size_t>(chunks));
  tbb::parallel_for(Eigen::Index{0}, chunks, [&](Eigen::Index k) {
    const Eigen::Index begin = k * kChunk, length = std::min(kChunk, a.size() - begin);
    partial[static_cast<std::size_t>(k)] = a.segment(begin, length).dot(b.segment(begin, length));
  });
  return std::accumulate(partial.begin(), partial.end(), 0.0);
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

// The per-vertex factors of H and b (see the top of this file), in normalised units, over the
// vertices renumbered breadth-first (`local` below, breadth_first_order): the operator gathers over
// one-rings, and in a mesh's own order the neighbours of a vertex can be anywhere in memory
// (the subdivided test mesh, amo.off). Measured: the iteration took 2-3x longer per vertex on
// those meshes than on one whose file order is local (horse-48k).
struct Terms {
  Index n = 0;
  std::vector<Index> original;          // local index -> mesh vertex
  std::vector<Index> local;             // mesh vertex -> local index
  std::vector<Index> ring_start, ring;  // one-rings in local indices
  std::vector<char> fixed;
  std::vector<Sym3> K;  // K_i
  std::vector<Sym3> G;  // diagonal block of G: deg(i) K_i + sum_j K_j
  std::vector<Sym3> P;  // 1/|E| times the tangent projector
  std::vector<Sym3> D;  // F_sd and pull
  std::vector<double> smooth, inv_degree;
  std::vector<Vector3> rest;  // fairness target r_i

  [[nodiscard]] std::pair<const Index*, const Index*> one_ring(Index i) const {
    return {ring.data() + ring_start[static_cast<std::size_t>(i)],
            ring.data() + ring_start[static_cast<std::size_t>(i) + 1]};
  }
  /// Calls visit(j) for i and then each vertex of its one-ring: the vertices whose rows of
  /// G and L involve i.
  template <class Visit>
  void for_each_in_star(Index i, Visit&& visit) const {
    visit(i);
    const auto [begin, end] = one_ring(i);
    for (const Index* j = begin; j != end; ++j) visit(*j);
  }
};

// Vertices sorted by the Morton code of their position (21 bits per axis), ties by index.
std::vector<Index> space_filling_order(const Vertices& P) {
  const Index n = static_cast<Index>(P.rows());
  std::vector<std::pair<std::uint64_t, Index>> keys(static_cast<std::size_t>(n));
  if (n == 0) return {};
  const Eigen::RowVector3d low = P.colwise().minCoeff(), high = P.colwise().maxCoeff();
  const double extent = std::max((high - low).maxCoeff(), 1e-300);
  auto spread = [](std::uint64_t v) {  // 21 bits -> every third bit of 63
    v &= 0x1fffffULL;
    v = (v | v << 32) & 0x1f00000000ffffULL;
    v = (v | v << 16) & 0x1f0000ff0000ffULL;
    v = (v | v << 8) & 0x100f00f00f00f00fULL;
    v = (v | v << 4) & 0x10c30c30c30c30c3ULL;
    v = (v | v << 2) & 0x1249249249249249ULL;
    return v;
  };
  parallel_vertices(n, [&](Index i) {
    std::uint64_t code = 0;
    for (int c = 0; c < 3; ++c) {
      const double unit = (P(i, c) - low[c]) / extent;
      code |= spread(static_cast<std::uint64_t>(std::clamp(unit, 0.0, 1.0) * 2097151.0)) << c;
    }
    keys[static_cast<std::size_t>(i)] = {code, i};
  });
  tbb::parallel_sort(keys.begin(), keys.end());  // keys are unique, so the order is too
  std::vector<Index> order(static_cast<std::size_t>(n));
  for (std::size_t k = 0; k < keys.size(); ++k) order[k] = keys[k].second;
  return order;
}

// Breadth-first (Cuthill-McKee) order of the vertex graph, each component started from its
// first vertex in `seed_order` (the Morton order: a vertex near a corner of the bounding box,
// so the breadth-first levels stay short). Every neighbour of a vertex is then within about
// one level's width of it in memory, a few hundred to a few thousand vertices, so the
// operator's gathers stay in the 2 MiB L2 cache; in Morton order a fraction of them jump far
// (the curve's seams). Measured per iteration, 1 thread: amo 11.6 -> 8.5 ms; armadillo-1M,
// 2 threads: 126 -> 77 ms.
std::vector<Index> breadth_first_order(const Topology& topology, const std::vector<Index>& seed_order) {
  const auto n = seed_order.size();
  std::vector<Index> order;
  order.reserve(n);
  std::vector<char> seen(n, 0);
  for (const Index seed : seed_order) {
    if (seen[static_cast<std::size_t>(seed)]) continue;
    seen[static_cast<std::size_t>(seed)] = 1;
    std::size_t head = order.size();
    order.push_back(seed);
    while (head < order.size()) {
      const auto [begin, end] = topology.ring(order[head++]);
      for (const Index* j = begin; j != end; ++j) {
        if (seen[static_cast<std::size_t>(*j)]) continue;
        seen[static_cast<std::size_t>(*j)] = 1;
        order.push_back(*j);
      }
    }
  }
  return order;
}

Terms make_terms(const Topology& topology, const std::vector<char>& fixed, const FlowFrame& frame,
                 const EnergyWeights& weights, std::vector<Index> order) {
  Terms t;
  t.n = static_cast<Index>(frame.P.rows());
  const auto n = static_cast<std::size_t>(t.n);
  t.original = std::move(order);
  t.local.resize(n);
  for (std::size_t k = 0; k < n; ++k) t.local[static_cast<std::size_t>(t.original[k])] = static_cast<Index>(k);
  t.ring_start.resize(n + 1);
  t.ring_start[0] = 0;
  for (std::size_t k = 0; k < n; ++k) t.ring_start[k + 1] = t.ring_start[k] + topology.valence(t.original[k]);
  t.ring.resize(static_cast<std::size_t>(t.ring_start[n]));
  t.fixed.resize(n);
  parallel_vertices(t.n, [&](Index k) {
    const Index v = t.original[static_cast<std::size_t>(k)];
    t.fixed[static_cast<std::size_t>(k)] = fixed[static_cast<std::size_t>(v)];
    const auto [begin, end] = topology.ring(v);
    Index* out = t.ring.data() + t.ring_start[static_cast<std::size_t>(k)];
    for (const Index* j = begin; j != end; ++j) *out++ = t.local[static_cast<std::size_t>(*j)];
  });
  t.K.resize(n);
  t.G.resize(n);
  t.P.resize(n);
  t.D.resize(n);
  t.smooth.resize(n);
  t.inv_degree.resize(n);
  t.rest.resize(n);
  const Curvature& c = frame.curvature;
  const double nv = std::max<double>(t.n, 1);
  const double w_em = topology.num_edges() > 0 ? 1.0 / topology.num_edges() : 0.0;
  const double w_sd = weights.lambda / nv, w_pull = weights.epsilon * weights.lambda / nv;
  parallel_vertices(t.n, [&](Index k) {
    const auto v = static_cast<std::size_t>(k);
    const Index i = t.original[v];
    const Vector3 t1 = c.T1.row(i).transpose(), t2 = c.T2.row(i).transpose(), normal = c.N.row(i).transpose();
    t.K[v] = Sym3(Matrix3(std::abs(c.k1[i]) * t1 * t1.transpose() + std::abs(c.k2[i]) * t2 * t2.transpose()));
    t.P[v] = Sym3(Matrix3(w_em * (t1 * t1.transpose() + t2 * t2.transpose())));
    Matrix3 distance =
        w_sd * (distance_coefficient(frame.d, c.k1[i]) * t1 * t1.transpose() +
                distance_coefficient(frame.d, c.k2[i]) * t2 * t2.transpose() + normal * normal.transpose());
    distance.diagonal().array() += w_pull;
    t.D[v] = Sym3(distance);
    const Index degree = topology.valence(i);
    t.inv_degree[v] = degree > 0 ? 1.0 / degree : 0.0;
    t.smooth[v] = degree > 0 ? weights.mu * std::exp(-(std::abs(c.k1[i]) + std::abs(c.k2[i]))) / nv : 0.0;
    t.rest[v].setZero();
    if (weights.fairness_target == FairnessTarget::InputNormal && degree > 0) {
      Vector3 mean = Vector3::Zero();
      const auto [begin, end] = topology.ring(i);
      for (const Index* j = begin; j != end; ++j) mean += frame.P.row(*j).transpose();  // mesh indices
      const Vector3 umbrella = frame.P.row(i).transpose() - mean * t.inv_degree[v];
      t.rest[v] = umbrella.dot(normal) * normal;
    }
  });
  parallel_vertices(t.n, [&](Index i) {
    const auto [begin, end] = t.one_ring(i);
    Matrix3 sum = static_cast<double>(end - begin) * t.K[static_cast<std::size_t>(i)].full();
    for (const Index* j = begin; j != end; ++j) sum += t.K[static_cast<std::size_t>(*j)].full();
    t.G[static_cast<std::size_t>(i)] = Sym3(sum);
  });
  return t;
}

// A vector over mesh vertices (3 per vertex) in local order, and back.
Vector to_local(const Terms& t, const double* x) {
  Vector out(3 * static_cast<Eigen::Index>(t.n));
  parallel_vertices(t.n, [&](Index k) {
    out.segment<3>(3 * static_cast<Eigen::Index>(k)) =
        Eigen::Map<const Vector3>(x + 3 * static_cast<std::ptrdiff_t>(t.original[static_cast<std::size_t>(k)]));
  });
  return out;
}
void add_from_local(const Terms& t, const Vector& x, double* out) {
  parallel_vertices(t.n, [&](Index k) {
    Eigen::Map<Vector3>(out + 3 * static_cast<std::ptrdiff_t>(t.original[static_cast<std::size_t>(k)])) +=
        x.segment<3>(3 * static_cast<Eigen::Index>(k));
  });
}

// The block G_iu of G for u in the star (one-ring and itself) of i.
Matrix3 g_block(const Terms& t, Index i, Index u) {
  return i == u ? t.G[static_cast<std::size_t>(i)].full()
                : Matrix3(-(t.K[static_cast<std::size_t>(i)].full() + t.K[static_cast<std::size_t>(u)].full()));
}
// The entry L_iu of the Laplacian.
double l_entry(const Terms& t, Index i, Index u) {
  return i == u ? 1.0 : -t.inv_degree[static_cast<std::size_t>(i)];
}

// Vertices per chunk of the reductions: sums are taken per fixed chunk and the chunks' sums
// added in order, so that their rounding does not depend on the threads.
constexpr Index kChunk = 2048;

// body(i) for every vertex i, returning the sum of its results (a double or an Eigen vector).
template <class T, class Body>
T chunked_sum(Index n, const T& zero, Body&& body) {
  const Index chunks = (n + kChunk - 1) / kChunk;
  std::vector<T> partial(static_cast<std::size_t>(chunks), zero);
  tbb::parallel_for(Index{0}, chunks, [&](Index k) {
    T sum = zero;
    for (Index i = k * kChunk, end = std::min(n, (k + 1) * kChunk); i < end; ++i) sum += body(i);
    partial[static_cast<std::size_t>(k)] = sum;
  });
  T total = zero;
  for (const T& part : partial) total += part;
  return total;
}

// H x (or, with with_d false and with_rest true, the part of H x - b that does not depend on D)
// without forming H: a pointwise pass (K x), then two passes over the one-rings: q = P G x and
// r = S (L x - R) (the weighted rows of F_tan and F_smo) with K q; then G q + L^T r + D x.
// The per-vertex factors are stored as symmetric 3x3 (48 bytes) and the dot product x . y that
// conjugate gradients need is summed in the last pass: about a third fewer bytes per iteration
// than full 3x3 blocks and separate passes, while applying K once per vertex and pass (applying
// it per neighbour instead, with no K x array, saved more bytes but cost more time: the
// iteration is as much bound by arithmetic as by memory here). Rows of fixed vertices are zero.
class Operator {
 public:
  explicit Operator(const Terms& terms) : t_(terms) {
    const auto n = static_cast<std::size_t>(t_.n);
    xkx_.resize(6 * n);
    qkr_.resize(9 * n);
    r_.resize(3 * static_cast<Eigen::Index>(n));
  }

  // Returns x . y (summed in chunks).
  double apply(const Vector& x, Vector& y, bool with_d, bool with_rest) {
    return passes(x, y, with_d, with_rest, [&](Index i) -> Vector3 { return at(x, i); });
  }

  // p = z + beta p, then y = H p; returns p . y. Conjugate gradients' direction update rides
  // on the first pass instead of a pass (and a round of tasks) of its own.
  double apply_updated(Vector& p, const Vector& z, double beta, Vector& y) {
    return passes(p, y, true, false, [&](Index i) -> Vector3 {
      const Vector3 updated = at(z, i) + beta * at(p, i);
      at(p, i) = updated;
      return updated;
    });
  }

 private:
  // first(i) gives x_i (and may write it) in the first pass; the later passes read x.
  template <class First>
  double passes(const Vector& x, Vector& y, bool with_d, bool with_rest, First&& first) {
    // What a vertex reads of its neighbours is interleaved in one record per vertex, so that a
    // neighbour costs one or two cache lines instead of one per array: the gathers' cache
    // misses were the hot spots of both one-ring passes.
    parallel_vertices(t_.n, [&](Index i) {
      const Vector3 xi = first(i);
      record<6>(xkx_, i).head<3>() = xi;
      record<6>(xkx_, i).tail<3>() = t_.K[static_cast<std::size_t>(i)] * xi;
    });
    parallel_vertices(t_.n, [&](Index i) {
      const auto v = static_cast<std::size_t>(i);
      const auto [begin, end] = t_.one_ring(i);
      Eigen::Matrix<double, 6, 1> sum = Eigen::Matrix<double, 6, 1>::Zero();
      for (const Index* j = begin; j != end; ++j) sum += record<6>(xkx_, *j);
      const Vector3 xi = at(x, i), sum_x = sum.head<3>();
      const Vector3 q = t_.P[v] * Vector3(t_.G[v] * xi - t_.K[v] * sum_x - sum.tail<3>());
      Vector3 laplacian = xi - t_.inv_degree[v] * sum_x;
      if (with_rest) laplacian -= t_.rest[v];
      const Vector3 r = t_.smooth[v] * laplacian;
      auto out = record<9>(qkr_, i);
      out.head<3>() = q;
      out.segment<3>(3) = t_.K[v] * q;
      out.tail<3>() = t_.inv_degree[v] * r;
      at(r_, i) = r;
    });
    // y = G q + L^T r (+ D x), G symmetric.
    return chunked_sum(t_.n, 0.0, [&](Index u) {
      const auto v = static_cast<std::size_t>(u);
      if (t_.fixed[v]) {
        at(y, u).setZero();
        return 0.0;
      }
      const auto [begin, end] = t_.one_ring(u);
      Eigen::Matrix<double, 9, 1> sum = Eigen::Matrix<double, 9, 1>::Zero();
      for (const Index* j = begin; j != end; ++j) sum += record<9>(qkr_, *j);
      const Vector3 xu = at(x, u), qu = record<9>(qkr_, u).head<3>();
      Vector3 out = t_.G[v] * qu - t_.K[v] * Vector3(sum.head<3>()) - sum.segment<3>(3) + at(r_, u) - sum.tail<3>();
      if (with_d) out += t_.D[v] * xu;
      at(y, u) = out;
      return xu.dot(out);
    });
  }

  template <int Size>
  static Eigen::Map<Eigen::Matrix<double, Size, 1>> record(std::vector<double>& data, Index i) {
    return Eigen::Map<Eigen::Matrix<double, Size, 1>>(data.data() + Size * static_cast<std::size_t>(i));
  }

  const Terms& t_;
  std::vector<double> xkx_;  // per vertex: x, K x
  std::vector<double> qkr_;  // per vertex: q, K q, r / degree
  Vector r_;
};

// The 3x3 diagonal block of H at free vertex u: sum over the star of u of G_iu P_i G_iu and
// S_i L_iu^2, plus D_u.
Matrix3 diagonal_block(const Terms& t, Index u) {
  Matrix3 block = t.D[static_cast<std::size_t>(u)].full();
  double laplacian = 0;
  auto add = [&](Index i) {
    const Matrix3 g = g_block(t, i, u);
    block.noalias() += g * t.P[static_cast<std::size_t>(i)].full() * g;
    laplacian += t.smooth[static_cast<std::size_t>(i)] * l_entry(t, i, u) * l_entry(t, i, u);
  };
  t.for_each_in_star(u, add);
  block.diagonal().array() += laplacian;
  return block;
}

// The size of the largest connected region of free vertices with |k1| + |k2| < kFlatCurvature.
Index largest_flat_region(const Terms& t) {
  const auto n = static_cast<std::size_t>(t.n);
  std::vector<char> open(n, 0);  // flat and not yet visited
  for (std::size_t i = 0; i < n; ++i) {
    const Sym3& k = t.K[i];  // trace(K) = |k1| + |k2|
    open[i] = !t.fixed[i] && k.xx + k.yy + k.zz < kFlatCurvature;
  }
  Index largest = 0;
  std::vector<Index> queue;
  for (Index seed = 0; seed < t.n; ++seed) {
    if (!open[static_cast<std::size_t>(seed)]) continue;
    open[static_cast<std::size_t>(seed)] = 0;
    queue.assign(1, seed);
    for (std::size_t head = 0; head < queue.size(); ++head) {
      const auto [begin, end] = t.one_ring(queue[head]);
      for (const Index* j = begin; j != end; ++j)
        if (open[static_cast<std::size_t>(*j)]) {
          open[static_cast<std::size_t>(*j)] = 0;
          queue.push_back(*j);
        }
    }
    largest = std::max(largest, static_cast<Index>(queue.size()));
  }
  return largest;
}

// The fine level of LinearSolver::Multilevel's preconditioner: M = B + Phi M_c Phi^T, with B
// the block-Jacobi inverse that the plain iteration uses, Phi the coarse space and M_c the
// additive multilevel operator (multigrid.h) of the Galerkin matrix H_c = Phi^T H Phi.
//
// Why: block-Jacobi leaves the smooth modes to the iteration, and where F_em vanishes (flat
// regions, K = 0) the only tangential stiffness is F_smo's bi-Laplacian, whose condition
// number grows like the region's diameter to the fourth power: fandisk's flat faces took 930
// iterations. Phi spans the translations of aggregates of one-rings, smoothed by one damped
// Jacobi step of the uniform Laplacian so that neighbouring basis functions overlap (with
// piecewise-constant ones the bi-Laplacian of a coarse function is large at aggregate borders).
// The Galerkin matrix is summed vertex by vertex from H's factors (flow_solver.cpp's top
// comment), not through H: H_c = (G Phi)^T P (G Phi) + (L Phi)^T S (L Phi) (x) I + Phi^T D Phi.
class MultilevelCorrection {
 public:
  explicit MultilevelCorrection(const Terms& t) : t_(t) {
    const auto n = static_cast<std::size_t>(t.n);
    const std::vector<int> aggregate = aggregate_nodes(t.ring_start, t.ring, t.fixed, count_);
    build_basis(aggregate);
    // Per vertex i (the rows of A at i, fixed vertices included): for each aggregate a whose
    // basis function is non-zero on the star of i, phi_a(i), the 3x3 block (G Phi_a)_i and the
    // entry (L phi_a)_i.
    // Sizes first (the distinct aggregates of the star's basis functions), so that the locals
    // take what they need: reserving the worst case per vertex tripled amo's peak memory.
    std::vector<std::uint32_t> local_size(n, 0);
    tbb::enumerable_thread_specific<std::vector<Index>> seen;
    parallel_vertices(t.n, [&](Index i) {
      std::vector<Index>& aggregates = seen.local();  // distinct, a handful: linear search
      aggregates.clear();
      t.for_each_in_star(i, [&](Index u) {
        for (const Weight& w : basis(u))
          if (std::find(aggregates.begin(), aggregates.end(), w.aggregate) == aggregates.end())
            aggregates.push_back(w.aggregate);
      });
      local_size[static_cast<std::size_t>(i)] = static_cast<std::uint32_t>(aggregates.size());
    });
    std::vector<std::size_t> local_start(n + 1, 0);
    for (std::size_t i = 0; i < n; ++i) local_start[i + 1] = local_start[i] + local_size[i];
    std::vector<Local> locals(local_start[n]);
    parallel_vertices(t.n, [&](Index i) {
      const auto v = static_cast<std::size_t>(i);
      Local* out = locals.data() + local_start[v];
      std::uint32_t size = 0;
      auto find = [&](Index a) -> Local& {
        for (std::uint32_t k = 0; k < size; ++k)
          if (out[k].aggregate == a) return out[k];
        out[size] = Local{a, 0, Matrix3::Zero(), 0};
        return out[size++];
      };
      const Matrix3 G = t.G[v].full(), K = t.K[v].full();
      for (const Weight& w : basis(i)) {
        Local& x = find(w.aggregate);
        x.phi = w.value;
        x.g += w.value * G;
        x.l += w.value;
      }
      const auto [begin, end] = t.one_ring(i);
      for (const Index* j = begin; j != end; ++j) {
        const Matrix3 coupling = K + t.K[static_cast<std::size_t>(*j)].full();
        for (const Weight& w : basis(*j)) {
          Local& x = find(w.aggregate);
          x.g -= w.value * coupling;
          x.l -= t.inv_degree[v] * w.value;
        }
      }
      std::sort(out, out + size, [](const Local& x, const Local& y) { return x.aggregate < y.aggregate; });
    });
    // The locals of each aggregate, by vertex (counting sort, so in vertex order).
    const auto na = static_cast<std::size_t>(count_);
    std::vector<std::size_t> touch_start(na + 1, 0);
    for (std::size_t i = 0; i < n; ++i)
      for (std::size_t k = 0; k < local_size[i]; ++k)
        ++touch_start[static_cast<std::size_t>(locals[local_start[i] + k].aggregate) + 1];
    for (std::size_t a = 0; a < na; ++a) touch_start[a + 1] += touch_start[a];
    std::vector<std::pair<Index, std::uint32_t>> touches(touch_start[na]);
    {
      std::vector<std::size_t> fill(touch_start.begin(), touch_start.end() - 1);
      for (std::size_t i = 0; i < n; ++i)
        for (std::uint32_t k = 0; k < local_size[i]; ++k)
          touches[fill[static_cast<std::size_t>(locals[local_start[i] + k].aggregate)]++] = {static_cast<Index>(i), k};
    }
    // Row a of the upper half of H_c: blocks (a, b), b >= a, summed over the vertices in order.
    const BlockSparseMatrix upper = build_block_rows(count_, count_, [&](int a, BlockRowAccumulator& row) {
      for (std::size_t m = touch_start[static_cast<std::size_t>(a)]; m < touch_start[static_cast<std::size_t>(a) + 1];
           ++m) {
        const auto [i, k] = touches[m];
        const auto v = static_cast<std::size_t>(i);
        const Local* local = locals.data() + local_start[v];
        const Local& x = local[k];
        const Matrix3 left = x.g * t.P[v].full();
        const Matrix3 D = t.D[v].full();                     // phi is 0 at fixed vertices, so their D drops out
        for (std::uint32_t q = k; q < local_size[v]; ++q) {  // sorted, so local[q].aggregate >= a
          const Local& y = local[q];
          Matrix3& block = row[y.aggregate];
          block.noalias() += left * y.g;
          block.diagonal().array() += t.smooth[v] * x.l * y.l;
          block.noalias() += (x.phi * y.phi) * D;
        }
      }
    });
    coarse_ = std::make_unique<AdditiveMultilevel>(symmetric_from_upper(upper));
    restricted_.resize(3 * count_);
  }

  // z += Phi M_c Phi^T r; returns r . z (summed in chunks, as every dot product here).
  double add_to(const Vector& r, Vector& z) {
    auto restrict_to = [&](Index a) {
      Vector3 sum = Vector3::Zero();
      for (std::size_t k = member_start_[static_cast<std::size_t>(a)];
           k < member_start_[static_cast<std::size_t>(a) + 1]; ++k)
        sum += members_[k].value * at(r, members_[k].aggregate);  // .aggregate holds the vertex here
      at(restricted_, a) = sum;
    };
    if (count_ < kSerialAggregatesBelow) {
      for (Index a = 0; a < count_; ++a) restrict_to(a);
    } else {
      parallel_vertices(count_, restrict_to);
    }
    coarse_->apply(restricted_, coarse_solution_);
    return chunked_sum(t_.n, 0.0, [&](Index i) {
      Vector3 sum = Vector3::Zero();
      for (const Weight& w : basis(i)) sum += w.value * at(coarse_solution_, w.aggregate);
      at(z, i) += sum;
      return at(r, i).dot(at(z, i));
    });
  }

 private:
  struct Weight {
    Index aggregate;
    double value;
  };
  struct Local {
    Index aggregate;
    double phi;  // phi_a(i)
    Matrix3 g;   // (G Phi_a)_i
    double l;    // (L phi_a)_i
  };
  // Damping of the Jacobi step. Measured, multilevel iterations on fandisk / spot /
  // max-planck-5k: 0.4: 158 / 85 / 73; 2/3 (the textbook value): 129 / 74 / 68; 0.9: 114 / 69 /
  // 65; 1.1: 162 / 72 / 68. At 1 a vertex surrounded by other aggregates loses its own.
  static constexpr double kBasisSmoothing = 0.9;
  // Restriction in the calling thread below this many aggregates (tasks cost more).
  static constexpr Index kSerialAggregatesBelow = 2048;

  std::span<const Weight> basis(Index i) const {
    const auto v = static_cast<std::size_t>(i);
    return {basis_.data() + basis_start_[v], basis_size_[v]};
  }

  // phi_a = (I - omega (I - W)) chi_a on free vertices, W the one-ring average, chi_a the
  // indicator of aggregate a; stored per vertex (sorted by aggregate) and per aggregate.
  void build_basis(const std::vector<int>& aggregate) {
    const auto n = static_cast<std::size_t>(t_.n);
    basis_start_.assign(n + 1, 0);
    for (std::size_t i = 0; i < n; ++i)
      basis_start_[i + 1] = basis_start_[i] + 1 + static_cast<std::size_t>(t_.ring_start[i + 1] - t_.ring_start[i]);
    basis_.resize(basis_start_[n]);
    basis_size_.assign(n, 0);
    parallel_vertices(t_.n, [&](Index i) {
      const auto v = static_cast<std::size_t>(i);
      if (t_.fixed[v]) return;
      Weight* out = basis_.data() + basis_start_[v];
      std::size_t size = 0;
      auto add = [&](Index a, double value) {
        for (std::size_t k = 0; k < size; ++k)
          if (out[k].aggregate == a) {
            out[k].value += value;
            return;
          }
        out[size++] = {a, value};
      };
      add(aggregate[v], 1 - kBasisSmoothing);
      const auto [begin, end] = t_.one_ring(i);
      const double w = kBasisSmoothing * t_.inv_degree[v];
      for (const Index* j = begin; j != end; ++j)
        if (aggregate[static_cast<std::size_t>(*j)] >= 0) add(aggregate[static_cast<std::size_t>(*j)], w);
      std::sort(out, out + size, [](const Weight& x, const Weight& y) { return x.aggregate < y.aggregate; });
      basis_size_[v] = size;
    });
    const auto na = static_cast<std::size_t>(count_);
    member_start_.assign(na + 1, 0);
    for (std::size_t i = 0; i < n; ++i)
      for (const Weight& w : basis(static_cast<Index>(i))) ++member_start_[static_cast<std::size_t>(w.aggregate) + 1];
    for (std::size_t a = 0; a < na; ++a) member_start_[a + 1] += member_start_[a];
    members_.resize(member_start_[na]);
    std::vector<std::size_t> fill(member_start_.begin(), member_start_.end() - 1);
    for (std::size_t i = 0; i < n; ++i)
      for (const Weight& w : basis(static_cast<Index>(i)))
        members_[fill[static_cast<std::size_t>(w.aggregate)]++] = {static_cast<Index>(i), w.value};
  }

  const Terms& t_;
  int count_ = 0;
  std::vector<std::size_t> basis_start_, basis_size_, member_start_;
  std::vector<Weight> basis_;    // per vertex: (aggregate, phi_a(i))
  std::vector<Weight> members_;  // per aggregate: (vertex, phi_a(i))
  std::unique_ptr<AdditiveMultilevel> coarse_;
  Vector restricted_, coarse_solution_;
};

// The multilevel preconditioner, or null if its coarsest matrix lost definiteness to rounding
// (degenerate input): block-Jacobi alone still converges, only more slowly.
std::unique_ptr<MultilevelCorrection> make_multilevel(const Terms& terms) {
  try {
    return std::make_unique<MultilevelCorrection>(terms);
  } catch (const std::runtime_error&) {
    return nullptr;
  }
}

struct IterationResult {
  int iterations = 0;
  bool converged = false;
};

// Preconditioned conjugate gradients from d = 0 (the input positions). Each run() continues
// for at most max_iterations, stopping when |r| <= tolerance |b|. The vector updates, the
// preconditioner and the two dot products they need share one pass (memory traffic, as in
// Operator).
class ConjugateGradients {
 public:
  ConjugateGradients(const Terms& terms, Operator& op, const Vector& b, MultilevelCorrection* multilevel)
      : t_(terms), op_(op), multilevel_(multilevel) {
    inverse_.resize(static_cast<std::size_t>(t_.n));
    parallel_vertices(t_.n, [&](Index u) {
      const auto v = static_cast<std::size_t>(u);
      if (!t_.fixed[v]) inverse_[v] = Sym3(Matrix3(diagonal_block(t_, u).inverse()));
    });
    d_.setZero(b.size());
    r_ = b;
    z_.resize(b.size());
    hp_.resize(b.size());
    rz_ = chunked_sum(t_.n, 0.0, [&](Index i) {
      at(z_, i) = inverse_[static_cast<std::size_t>(i)] * at(r_, i);
      return at(r_, i).dot(at(z_, i));
    });
    if (multilevel_) rz_ = multilevel_->add_to(r_, z_);
    p_ = z_;
    b_norm_ = std::sqrt(dot(b, b));
    r_norm_ = b_norm_;
  }

  IterationResult run(int max_iterations, double tolerance) {
    IterationResult result;
    const double target = tolerance * b_norm_;
    if (r_norm_ <= target) {
      result.converged = true;
      return result;
    }
    while (result.iterations < max_iterations) {
      // p = z + beta p is still to be done when a previous iteration computed beta.
      const double curvature =
          pending_beta_ ? op_.apply_updated(p_, z_, *pending_beta_, hp_) : op_.apply(p_, hp_, true, false);
      pending_beta_.reset();
      if (!(curvature > 0)) break;  // H is positive definite; only rounding at convergence gets here
      const double alpha = rz_ / curvature;
      alphas_.push_back(alpha);
      // d += alpha p, r -= alpha H p, z = M^-1 r; sums of r.r and r.z.
      const Eigen::Vector2d sums = chunked_sum(t_.n, Eigen::Vector2d::Zero().eval(), [&](Index i) {
        at(d_, i) += alpha * at(p_, i);
        const Vector3 r = at(r_, i) - alpha * at(hp_, i);
        const Vector3 z = inverse_[static_cast<std::size_t>(i)] * r;
        at(r_, i) = r;
        at(z_, i) = z;
        return Eigen::Vector2d(r.squaredNorm(), r.dot(z));
      });
      r_norm_ = std::sqrt(sums[0]);
      double rz = sums[1];
      if (multilevel_) rz = multilevel_->add_to(r_, z_);
      ++result.iterations;
      ++total_iterations_;
      if (r_norm_ <= target) {
        result.converged = true;
        break;
      }
      pending_beta_ = rz / rz_;
      betas_.push_back(*pending_beta_);
      rz_ = rz;
    }
    return result;
  }

  // The iterations that the current preconditioner is predicted to need in all, from the
  // extreme eigenvalues of the Lanczos matrix of the iterations so far (Saad, Iterative
  // Methods, 6.7.3): 1/2 sqrt(kappa) ln(2 / tolerance), the conjugate-gradient bound. After a
  // few dozen iterations the smallest eigenvalue is still overestimated, so this is a lower
  // bound, and the flat meshes' counts are underestimated most.
  [[nodiscard]] double predicted_iterations(double tolerance) const {
    const auto k = static_cast<Eigen::Index>(std::min(alphas_.size(), betas_.size() + 1));
    if (k < 2) return 0;
    Eigen::MatrixXd T = Eigen::MatrixXd::Zero(k, k);
    for (Eigen::Index j = 0; j < k; ++j) {
      const auto u = static_cast<std::size_t>(j);
      T(j, j) = 1 / alphas_[u] + (j > 0 ? betas_[u - 1] / alphas_[u - 1] : 0.0);
      if (j + 1 < k) T(j, j + 1) = T(j + 1, j) = std::sqrt(betas_[u]) / alphas_[u];
    }
    const Eigen::VectorXd eigenvalues =
        Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(T, Eigen::EigenvaluesOnly).eigenvalues();
    const double kappa = eigenvalues[k - 1] / std::max(eigenvalues[0], 1e-300);
    return 0.5 * std::sqrt(kappa) * std::log(2 / tolerance);
  }

  // Continues from the current iterate with the multilevel preconditioner (a restart: the
  // search directions so far were conjugate for the old one).
  void use_multilevel(MultilevelCorrection* multilevel) {
    multilevel_ = multilevel;
    parallel_vertices(t_.n, [&](Index i) { at(z_, i) = inverse_[static_cast<std::size_t>(i)] * at(r_, i); });
    rz_ = multilevel_->add_to(r_, z_);
    p_ = z_;
    pending_beta_.reset();
    alphas_.clear();
    betas_.clear();
  }

  const Vector& solution() const { return d_; }
  int total_iterations() const { return total_iterations_; }

 private:
  const Terms& t_;
  Operator& op_;
  MultilevelCorrection* multilevel_;    // null: block-Jacobi alone
  std::optional<double> pending_beta_;  // p = z + beta p, done by the next operator application
  std::vector<double> alphas_, betas_;  // of the iterations since the last preconditioner change
  std::vector<Sym3> inverse_;           // of H's diagonal blocks; zero at fixed vertices
  Vector d_, r_, z_, p_, hp_;
  double rz_ = 0, b_norm_ = 0, r_norm_ = 0;
  int total_iterations_ = 0;
};

}  // namespace

struct FlowSystemSolver::Impl {
  const Topology& topology;
  std::vector<char> fixed;
  LinearSolver kind;
  double tolerance;
  // Local numbering (Terms), chosen at the first solve and kept: the pattern and the ordering
  // below are in it.
  std::vector<Index> order;
  std::vector<Index> free_index;   // local index -> free index, -1 for fixed vertices
  std::vector<Index> free_vertex;  // free index -> local index
  // Two-ring pattern of H over the free vertices, lower half by rows (= upper half by
  // columns): row a holds the free indices b <= a.
  std::vector<std::int64_t> row_start;
  std::vector<Index> row_columns;
  bool pattern_built = false;
  double scalar_factor_entries = -1;  // CHOLMOD's predicted fill of the vertex graph
  std::vector<SuiteSparse_long> vertex_permutation;
  cholmod_common common{};
  cholmod_factor* factor = nullptr;

  Impl(const Topology& t, std::vector<char> f, LinearSolver k, double tol)
      : topology(t), fixed(std::move(f)), kind(k), tolerance(tol) {
    cholmod_l_start(&common);
    // Supernodal factorisation calls BLAS, and OpenBLAS spins forever when it cannot map its
    // work buffer (seen under `ulimit -v`, issue 12). Under an address-space limit the
    // simplicial method, which needs no BLAS, reports running out of memory instead.
    common.supernodal = address_space_is_limited() ? CHOLMOD_SIMPLICIAL : CHOLMOD_SUPERNODAL;
    common.print = 0;  // failures become exceptions (one line from the CLI), never CHOLMOD's own prints
  }
  ~Impl() {
    if (factor) cholmod_l_free_factor(&factor, &common);
    cholmod_l_finish(&common);
  }
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;

  [[nodiscard]] Index num_free() const { return static_cast<Index>(std::count(fixed.begin(), fixed.end(), 0)); }

  void number_vertices(const Vertices& P) {
    if (!order.empty() || P.rows() == 0) return;
    order = breadth_first_order(topology, space_filling_order(P));
    free_index.assign(order.size(), -1);
    for (std::size_t k = 0; k < order.size(); ++k) {
      if (fixed[static_cast<std::size_t>(order[k])]) continue;
      free_index[k] = static_cast<Index>(free_vertex.size());
      free_vertex.push_back(static_cast<Index>(k));
    }
  }
  void build_pattern(const Terms& terms);
  void order_vertices(const Terms& terms);
  cholmod_sparse* assemble(const Terms& terms);
  Vector factor_and_solve(const Terms& terms, const Vector& b, FlowReport& report);
};

// Column a of the upper half holds the free vertices b <= a that share a star with a.
void FlowSystemSolver::Impl::build_pattern(const Terms& t) {
  if (pattern_built) return;
  const Index m = num_free(), n = static_cast<Index>(fixed.size());
  std::vector<std::vector<Index>> rows(static_cast<std::size_t>(m));
  tbb::enumerable_thread_specific<std::vector<Index>> marks(
      [n] { return std::vector<Index>(static_cast<std::size_t>(n), -1); });
  parallel_vertices(m, [&](Index a) {
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
  parallel_vertices(m, [&](Index a) {
    const auto& row = rows[static_cast<std::size_t>(a)];
    std::copy(row.begin(), row.end(), row_columns.begin() + row_start[static_cast<std::size_t>(a)]);
  });
  pattern_built = true;
}

// A fill-reducing ordering of the free vertex graph (CHOLMOD's default choice: AMD, and METIS
// too when AMD's fill is large), and its predicted fill.
void FlowSystemSolver::Impl::order_vertices(const Terms& terms) {
  if (!vertex_permutation.empty() || num_free() == 0) return;
  build_pattern(terms);
  const Index m = num_free();
  cholmod_sparse* pattern = cholmod_l_allocate_sparse(static_cast<std::size_t>(m), static_cast<std::size_t>(m),
                                                      row_columns.size(), 1, 1, 1, CHOLMOD_PATTERN, &common);
  if (!pattern) throw std::bad_alloc();
  auto* p = static_cast<SuiteSparse_long*>(pattern->p);
  auto* i = static_cast<SuiteSparse_long*>(pattern->i);
  std::copy(row_start.begin(), row_start.end(), p);
  std::copy(row_columns.begin(), row_columns.end(), i);
  common.nmethods = 0;
  common.postorder = 1;
  cholmod_factor* symbolic = cholmod_l_analyze(pattern, &common);
  if (!symbolic) {
    cholmod_l_free_sparse(&pattern, &common);
    throw_if_out_of_memory(common);
    throw std::runtime_error("vertex flow: CHOLMOD could not order the vertex graph");
  }
  scalar_factor_entries = common.lnz;
  const auto* perm = static_cast<const SuiteSparse_long*>(symbolic->Perm);
  vertex_permutation.assign(perm, perm + m);
  cholmod_l_free_factor(&symbolic, &common);
  cholmod_l_free_sparse(&pattern, &common);
}

// H over the free vertices, upper half by columns, with 3x3 blocks expanded: column 3a + r
// holds rows 3b + c for b < a, and b = a with c <= r.
cholmod_sparse* FlowSystemSolver::Impl::assemble(const Terms& t) {
  build_pattern(t);
  const Index m = num_free(), n = static_cast<Index>(fixed.size());
  std::vector<SuiteSparse_long> column_start(3 * static_cast<std::size_t>(m) + 1, 0);
  for (Index a = 0; a < m; ++a) {
    const auto off_diagonal =
        3 * (row_start[static_cast<std::size_t>(a) + 1] - row_start[static_cast<std::size_t>(a)] - 1);
    for (int r = 0; r < 3; ++r) {
      const std::size_t column = 3 * static_cast<std::size_t>(a) + static_cast<std::size_t>(r);
      column_start[column + 1] = column_start[column] + off_diagonal + r + 1;
    }
  }
  const auto entries = static_cast<std::size_t>(column_start.back());
  cholmod_sparse* A = cholmod_l_allocate_sparse(3 * static_cast<std::size_t>(m), 3 * static_cast<std::size_t>(m),
                                                entries, 1, 1, 1, CHOLMOD_REAL, &common);
  if (!A) throw std::bad_alloc();
  std::copy(column_start.begin(), column_start.end(), static_cast<SuiteSparse_long*>(A->p));
  auto* rows = static_cast<SuiteSparse_long*>(A->i);
  auto* values = static_cast<double*>(A->x);
  tbb::enumerable_thread_specific<std::vector<std::int64_t>> positions(
      [n] { return std::vector<std::int64_t>(static_cast<std::size_t>(n), -1); });
  tbb::enumerable_thread_specific<std::vector<Matrix3>> scratch;
  parallel_vertices(m, [&](Index a) {
    std::vector<std::int64_t>& position = positions.local();
    std::vector<Matrix3>& blocks = scratch.local();
    const auto first = row_start[static_cast<std::size_t>(a)], last = row_start[static_cast<std::size_t>(a) + 1];
    blocks.assign(static_cast<std::size_t>(last - first), Matrix3::Zero());
    for (auto k = first; k < last; ++k)
      position[static_cast<std::size_t>(
          free_vertex[static_cast<std::size_t>(row_columns[static_cast<std::size_t>(k)])])] = k - first;
    const Index u = free_vertex[static_cast<std::size_t>(a)];
    // Block (u, w) = sum over i whose star holds u and w of G_iu P_i G_iw + S_i L_iu L_iw I.
    auto add_star = [&](Index i) {
      const Matrix3 left = g_block(t, i, u) * t.P[static_cast<std::size_t>(i)].full();
      const double l_u = t.smooth[static_cast<std::size_t>(i)] * l_entry(t, i, u);
      auto add = [&](Index w) {
        const std::int64_t k = position[static_cast<std::size_t>(w)];
        if (k < 0) return;  // fixed, or w > u
        Matrix3& block = blocks[static_cast<std::size_t>(k)];
        block.noalias() += left * g_block(t, i, w);
        block.diagonal().array() += l_u * l_entry(t, i, w);
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
          rows[out] = 3 * static_cast<SuiteSparse_long>(b) + c;
          values[out] = blocks[static_cast<std::size_t>(k - first)](r, c);
          ++out;
        }
      }
    }
  });
  return A;
}

Vector FlowSystemSolver::Impl::factor_and_solve(const Terms& terms, const Vector& b, FlowReport& report) {
  const Index m = num_free();
  auto start = Clock::now();
  order_vertices(terms);
  cholmod_sparse* A = assemble(terms);
  report.seconds_assembly += seconds_since(start);

  start = Clock::now();
  use_single_threaded_blas();
  if (!factor) {
    std::vector<SuiteSparse_long> permutation(3 * static_cast<std::size_t>(m));
    for (std::size_t k = 0; k < vertex_permutation.size(); ++k)
      for (int c = 0; c < 3; ++c) permutation[3 * k + static_cast<std::size_t>(c)] = 3 * vertex_permutation[k] + c;
    common.nmethods = 1;
    common.method[0].ordering = CHOLMOD_GIVEN;
    common.postorder = 1;
    factor = cholmod_l_analyze_p(A, permutation.data(), nullptr, 0, &common);
  }
  const bool ok = factor && cholmod_l_factorize(A, factor, &common) && common.status == CHOLMOD_OK;
  cholmod_l_free_sparse(&A, &common);
  throw_if_out_of_memory(common);
  if (!ok) throw std::runtime_error("vertex flow: the normal matrix is not positive definite");
  report.seconds_factorization += seconds_since(start);

  start = Clock::now();
  cholmod_dense* rhs = cholmod_l_allocate_dense(3 * static_cast<std::size_t>(m), 1, 3 * static_cast<std::size_t>(m),
                                                CHOLMOD_REAL, &common);
  if (!rhs) throw std::bad_alloc();
  auto* rhs_values = static_cast<double*>(rhs->x);
  for (Index a = 0; a < m; ++a)
    for (int c = 0; c < 3; ++c)
      rhs_values[3 * a + c] = b[3 * static_cast<Eigen::Index>(free_vertex[static_cast<std::size_t>(a)]) + c];
  cholmod_dense* x = cholmod_l_solve(CHOLMOD_A, factor, rhs, &common);
  cholmod_l_free_dense(&rhs, &common);
  throw_if_out_of_memory(common);
  if (!x) throw std::runtime_error("vertex flow: the triangular solves failed");
  Vector d = Vector::Zero(b.size());
  const auto* x_values = static_cast<const double*>(x->x);
  for (Index a = 0; a < m; ++a)
    for (int c = 0; c < 3; ++c)
      d[3 * static_cast<Eigen::Index>(free_vertex[static_cast<std::size_t>(a)]) + c] = x_values[3 * a + c];
  cholmod_l_free_dense(&x, &common);
  report.seconds_solve += seconds_since(start);
  return d;
}

FlowSystemSolver::FlowSystemSolver(const Topology& topology, std::vector<char> fixed, LinearSolver kind,
                                   double tolerance)
    : impl_(std::make_unique<Impl>(topology, std::move(fixed), kind, tolerance)) {
  if (!(tolerance > 0 && tolerance < 1)) throw std::invalid_argument("vertex flow: solver_tolerance must be in (0, 1)");
}

FlowSystemSolver::~FlowSystemSolver() = default;

Vertices FlowSystemSolver::solve(const FlowFrame& frame, const EnergyWeights& weights, FlowReport& report) {
  Impl& s = *impl_;
  const Index m = s.num_free();
  auto start = Clock::now();
  s.number_vertices(frame.P);
  const Terms terms = make_terms(s.topology, s.fixed, frame, weights, s.order);
  Operator op(terms);
  // b = -(H P - D P) with the fairness targets: the negative gradient at d = 0.
  Vector b(3 * static_cast<Eigen::Index>(terms.n));
  op.apply(to_local(terms, frame.P.data()), b, false, true);
  b = -b;
  report.seconds_assembly += seconds_since(start);

  bool direct = s.kind == LinearSolver::Direct || (s.kind == LinearSolver::Automatic && m <= kDirectBelow);
  Vector d;
  LinearSolver used = LinearSolver::Direct;
  report.solver_iterations = 0;
  if (!direct && m > 0) {
    start = Clock::now();
    std::unique_ptr<MultilevelCorrection> multilevel;
    if (s.kind == LinearSolver::Multilevel ||
        (s.kind == LinearSolver::Automatic && largest_flat_region(terms) >= kFlatRegionForMultilevel))
      multilevel = make_multilevel(terms);
    ConjugateGradients cg(terms, op, b, multilevel.get());
    report.seconds_factorization += seconds_since(start);
    start = Clock::now();
    const int budget = static_cast<int>(std::ceil(kBudgetPerSqrtVertex * std::sqrt(static_cast<double>(m))));
    IterationResult result;
    if (s.kind == LinearSolver::Automatic && !multilevel) {
      // Block-Jacobi first; if the first iterations predict a long run, switch.
      result = cg.run(std::min(kProbeIterations, budget), s.tolerance);
      if (!result.converged && cg.predicted_iterations(s.tolerance) > kSwitchAbovePredicted) {
        report.seconds_solve += seconds_since(start);
        start = Clock::now();
        multilevel = make_multilevel(terms);
        if (multilevel) cg.use_multilevel(multilevel.get());
        report.seconds_factorization += seconds_since(start);
        start = Clock::now();
      }
    }
    if (!result.converged)
      result =
          cg.run((s.kind == LinearSolver::Automatic ? budget : kIterationCapFactor * budget) - cg.total_iterations(),
                 s.tolerance);
    if (!result.converged && s.kind == LinearSolver::Automatic) {
      // Fall back to the factorisation if it fits; otherwise keep iterating.
      report.seconds_solve += seconds_since(start);
      start = Clock::now();
      s.order_vertices(terms);
      report.seconds_factorization += seconds_since(start);
      start = Clock::now();
      if (9.0 * s.scalar_factor_entries * sizeof(double) <= kMaxFactorBytes) {
        direct = true;
      } else {
        result = cg.run((kIterationCapFactor - 1) * budget, s.tolerance);
      }
    }
    report.seconds_solve += seconds_since(start);
    report.solver_iterations = cg.total_iterations();
    if (!direct) d = cg.solution();
    used = direct ? LinearSolver::Direct : multilevel ? LinearSolver::Multilevel : LinearSolver::Iterative;
  }
  if (direct && m > 0) d = s.factor_and_solve(terms, b, report);
  if (m == 0) d = Vector::Zero(b.size());
  report.solver_used = used;

  // The relative residual of the normal equations, independent of the method.
  start = Clock::now();
  Vector residual(b.size());
  op.apply(d, residual, true, false);
  residual -= b;
  const double b_norm = std::sqrt(dot(b, b));
  report.solver_error = b_norm > 0 ? std::sqrt(dot(residual, residual)) / b_norm : 0.0;
  Vertices Y = frame.P;
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
