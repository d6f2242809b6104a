// Rusinkiewicz (2004) curvature estimation; see include/vertexflow/curvature.h for the
// conventions. Every pass is either "per face, write own slots" or "per vertex, gather from
// incident faces in the topology's fixed order", so results do not depend on thread count.
//
// Speed (a benchmark target: >= 5M vertices/s, bench/bench_curvature.cpp): the three heavy
// passes run on blocks of 64 faces or vertices as branch-free loops over lanes, which the
// compiler vectorises (AVX2 + FMA where the machine has it); they use a small scalar 3-vector
// (Vec3), which vectorises across lanes, where Eigen::Vector3d would pack within one vector.
// One 72-byte record per face is the only scratch memory, and large buffers get huge pages.
// One file of about 630 lines on purpose: every pass shares that record's layout and the lane
// helpers (Vec3, the SIMD clones), which would otherwise become an internal header of their own.
#include "vertexflow/curvature.h"

#include "vertexflow/manifold_split.h"

#include "common/huge_pages.h"
#include "numerics/parallel.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <stdexcept>

namespace vertexflow {
namespace {

using CornerAreas = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;

template <class Body>
void parallel_range(Index n, Body&& body) {
  parallel_for_index(n, body, 2048);
}

// The passes written as loops over blocks of lanes (the *_block functions) get an AVX2 + FMA
// clone next to the baseline one; the dynamic loader picks one per machine (GCC's
// target_clones). Blocks start at fixed indices and the tail block is padded, so every element
// is computed in the same lane whatever the thread partition: results do not depend on the
// thread count.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define VERTEXFLOW_SIMD_CLONES __attribute__((target_clones("arch=x86-64-v3", "default")))
#else
#define VERTEXFLOW_SIMD_CLONES
#endif
constexpr int kBlock = 64;

// Runs body(first, count) over [0, n) in blocks of kBlock, in parallel.
template <class Body>
void parallel_blocks(Index n, Body&& body) {
  const Index blocks = (n + kBlock - 1) / kBlock;
  tbb::parallel_for(tbb::blocked_range<Index>(0, blocks, 32), [&](const tbb::blocked_range<Index>& r) {
    for (Index b = r.begin(); b != r.end(); ++b)
      body(b * kBlock, static_cast<int>(std::min<Index>(kBlock, n - b * kBlock)));
  });
}

struct Vec3 {
  double x, y, z;
};
inline Vec3 operator+(Vec3 a, Vec3 b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
inline Vec3 operator-(Vec3 a, Vec3 b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
inline Vec3 operator-(Vec3 a) {
  return {-a.x, -a.y, -a.z};
}
inline Vec3 operator*(double s, Vec3 a) {
  return {s * a.x, s * a.y, s * a.z};
}
inline double dot(Vec3 a, Vec3 b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
inline Vec3 cross(Vec3 a, Vec3 b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline double squared_norm(Vec3 a) {
  return dot(a, a);
}

inline Vec3 row(const Vertices& M, Index i) {
  const double* p = M.data() + 3 * static_cast<std::ptrdiff_t>(i);
  return {p[0], p[1], p[2]};
}
inline void set_row(Vertices& M, Index i, Vec3 a) {
  double* p = M.data() + 3 * static_cast<std::ptrdiff_t>(i);
  p[0] = a.x;
  p[1] = a.y;
  p[2] = a.z;
}
inline const Index* face_row(const Faces& F, Index f) {
  return F.data() + 3 * static_cast<std::ptrdiff_t>(f);
}
inline int corner_of(const Faces& F, Index f, Index v) {
  const Index* face = face_row(F, f);
  return face[0] == v ? 0 : face[1] == v ? 1 : 2;
}

// Per-face geometry for the vertex normals and areas: the unnormalised face normal
// n = (p1 - p0) x (p2 - p0) (the cross product of the two edges at every corner), each
// corner's weight in its vertex normal (it contributes weight * n) and each corner's mixed
// area (Meyer et al. 2003). All zero for a degenerate face.
struct FaceGeometry {
  Vec3 normal;
  double weight[3];
  double area[3];
};

// Written without branches (flags are 0/1 doubles, and the divisors of a degenerate face are
// shifted off zero and its results multiplied by 0), so that face_geometry_block vectorises it.
// use_max: 1 for the Max1999 weighting, 0 for Area.
inline FaceGeometry face_geometry_kernel(Vec3 p0, Vec3 p1, Vec3 p2, double use_max) {
  // Edge k is opposite corner k; at corner k the two edges are -edge[k + 2] and edge[k + 1].
  const Vec3 edge[3] = {p2 - p1, p0 - p2, p1 - p0};
  FaceGeometry g;
  g.normal = cross(edge[2], -edge[1]);
  const double length = std::sqrt(squared_norm(g.normal));
  const double valid = static_cast<double>(length > 0), invalid = 1.0 - valid;
  const double squared[3] = {squared_norm(edge[0]), squared_norm(edge[1]), squared_norm(edge[2])};
  const double dots[3] = {-dot(edge[2], edge[1]), -dot(edge[0], edge[2]), -dot(edge[1], edge[0])};  // < 0: obtuse
  // Max1999: 1 / (|edge k+1|^2 |edge k+2|^2) = |edge k|^2 / (product of all three).
  const double inverse_product = 1.0 / (squared[0] * squared[1] * squared[2] + invalid);
  // Obtuse at k: half the face to k, a quarter to each other corner. At most one corner is
  // obtuse; if rounding makes two, the first counts.
  const double obtuse0 = static_cast<double>(dots[0] < 0);
  const double obtuse1 = static_cast<double>(dots[1] < 0) * (1.0 - obtuse0);
  const double obtuse2 = static_cast<double>(dots[2] < 0) * (1.0 - obtuse0) * (1.0 - obtuse1);
  const double obtuse[3] = {obtuse0, obtuse1, obtuse2};
  const double any_obtuse = obtuse0 + obtuse1 + obtuse2;
  const double quarter = 0.125 * length, inverse = 1.0 / (8.0 * length + invalid);
#pragma GCC unroll 3
  for (int k = 0; k < 3; ++k) {
    // Voronoi region of corner k: (|edge k+2|^2 cot(angle at k+2) + |edge k+1|^2 cot(angle at
    // k+1)) / 8, with cot(angle at m) = dots[m] / length.
    const double voronoi =
        (squared[(k + 2) % 3] * dots[(k + 2) % 3] + squared[(k + 1) % 3] * dots[(k + 1) % 3]) * inverse;
    g.area[k] = valid * ((1.0 - any_obtuse) * voronoi + any_obtuse * (quarter + obtuse[k] * quarter));
    g.weight[k] = valid * (use_max * squared[k] * inverse_product + (1.0 - use_max));
  }
  return g;
}

FaceGeometry face_geometry(Vec3 p0, Vec3 p1, Vec3 p2, NormalWeighting weighting) {
  FaceGeometry g = face_geometry_kernel(p0, p1, p2, weighting == NormalWeighting::Max1999 ? 1.0 : 0.0);
  if (weighting == NormalWeighting::Angle) {
    const double length = std::sqrt(squared_norm(g.normal));
    if (!(length > 0)) return g;
    const Vec3 p[3] = {p0, p1, p2};
    for (int k = 0; k < 3; ++k) {  // the corner's angle / length
      g.weight[k] = std::atan2(length, dot(p[(k + 1) % 3] - p[k], p[(k + 2) % 3] - p[k])) / length;
    }
  }
  return g;
}

FaceGeometry face_geometry(const Vertices& V, const Faces& F, Index f, NormalWeighting weighting) {
  const Index* face = face_row(F, f);
  return face_geometry(row(V, face[0]), row(V, face[1]), row(V, face[2]), weighting);
}

// A vertex's tangent frame (u, w, N): orthonormal, right-handed (w = N x u), chosen from N
// alone so that every pass derives the same frame without storing it. The construction is
// Duff et al., "Building an orthonormal basis, revisited" (JCGT 2017): unit by construction,
// no square root, and no branch (copysign), which keeps the vectorised pass 2 branch-free.
struct Frame {
  Vec3 u, w;
};
inline Frame vertex_frame(Vec3 n) {
  const double sign = std::copysign(1.0, n.z);
  const double a = -1.0 / (sign + n.z);
  const double b = n.x * n.y * a;
  return {{1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x}, {b, sign + n.y * n.y * a, -n.y}};
}

// The symmetric tensor (ku, kuv, kv) in a frame (u, w) rotated by phi from the frame (t, b) of
// II = [[e, f], [f, g]], with c = cos(phi) = u . t and s = sin(phi) = w . t: u = c t - s b and
// w = s t + c b, so the result is R^T II R with R = [[c, s], [-s, c]].
struct Tensor {
  double ku, kuv, kv;
};
inline Tensor rotate_tensor(double e, double f, double g, double c, double s) {
  const double cc = c * c, ss = s * s, cs = c * s;
  return {e * cc - 2 * f * cs + g * ss, (e - g) * cs + f * (cc - ss), e * ss + 2 * f * cs + g * cc};
}

// The tensor (e, f, g) given in the frame (t, N' x t) of the tangent plane of unit normal N',
// expressed in the frame (u, w) of the tangent plane of unit normal N: t is first carried into
// N's plane by the smallest rotation taking N' to N (Rusinkiewicz 2004, section 4). For t
// orthogonal to N', Rodrigues' formula reduces that rotation to
// t' = t - (N . t) / (1 + N' . N) (N' + N): one dot product instead of three cross products.
inline Tensor transport_tensor(double e, double f, double g, Vec3 t, Vec3 from_normal, Vec3 n, const Frame& frame) {
  const Vec3 moved = t - (dot(n, t) / (1.0 + dot(from_normal, n))) * (from_normal + n);
  return rotate_tensor(e, f, g, dot(frame.u, moved), dot(frame.w, moved));
}

// Faces whose normal is within this of the opposite of the vertex normal are folded over; their
// frame cannot be rotated meaningfully and they are left out of that vertex's average.
constexpr double kFoldedCosine = -1.0 + 1e-9;

// The scratch record of one face, reused by both per-face passes: pass 1 writes the face's
// FaceGeometry (read by the vertices' normal and area gather and by pass 2), then pass 2
// overwrites it with each corner's area-weighted tensor in its vertex's frame.
union FaceRecord {
  FaceGeometry geometry;
  Tensor corner[3];
};
static_assert(sizeof(FaceGeometry) == sizeof(Tensor[3]));

// Pass 1 for the faces [first, first + count), count <= kBlock: face_geometry_kernel for the
// Max1999 (max_weighting) or Area weighting, as a loop over lanes that the compiler vectorises
// (VERTEXFLOW_SIMD_CLONES).
VERTEXFLOW_SIMD_CLONES
void face_geometry_block(const Vertices& V, const Faces& F, Index first, int count, bool max_weighting,
                         FaceRecord* records) {
  constexpr int L = kBlock;
  alignas(64) double p[3][3][L], normal[3][L], weight[3][L], area[3][L];
  for (int i = 0; i < L; ++i) {
    const Index* face = face_row(F, first + (i < count ? i : count - 1));
    for (int k = 0; k < 3; ++k) {
      const double* pk = V.data() + 3 * static_cast<std::ptrdiff_t>(face[k]);
      for (int d = 0; d < 3; ++d) p[k][d][i] = pk[d];
    }
  }
  const double use_max = max_weighting ? 1.0 : 0.0;
  for (int i = 0; i < L; ++i) {
    const FaceGeometry g =
        face_geometry_kernel({p[0][0][i], p[0][1][i], p[0][2][i]}, {p[1][0][i], p[1][1][i], p[1][2][i]},
                             {p[2][0][i], p[2][1][i], p[2][2][i]}, use_max);
    normal[0][i] = g.normal.x;
    normal[1][i] = g.normal.y;
    normal[2][i] = g.normal.z;
    for (int k = 0; k < 3; ++k) {
      weight[k][i] = g.weight[k];
      area[k][i] = g.area[k];
    }
  }
  for (int i = 0; i < count; ++i) {
    FaceGeometry& g = records[first + i].geometry;
    g.normal = {normal[0][i], normal[1][i], normal[2][i]};
    for (int k = 0; k < 3; ++k) {
      g.weight[k] = weight[k][i];
      g.area[k] = area[k][i];
    }
  }
}

// The least-squares fit of one face's second fundamental form II = [[e, f], [f, g]]
// (Rusinkiewicz 2004, section 3): for each edge E from corner j to corner l,
// II (E.t, E.b) = ((N_l - N_j).t, (N_l - N_j).b), six equations in e, f, g, given by their
// normal equations [[uu, uv, 0], [uv, uu + vv, uv], [0, uv, vv]] (e, f, g) = r, in the face
// frame (t, face_normal x t) with t along edge 0. Without branches (fit_and_transport_block
// vectorises it): for a degenerate face (normal_squared or edge_squared 0) the frame is not
// finite, and the caller must not use the result.
struct FitSystem {
  Vec3 t, face_normal;
  double normal_squared, edge_squared;
  double uu, uv, vv, r0, r1, r2;
};
inline FitSystem fit_system(const Vec3 (&p)[3], const Vec3 (&n)[3]) {
  FitSystem s;
  // Edge k is opposite corner k: from corner k + 1 to corner k + 2.
  const Vec3 edge0 = p[2] - p[1], edge1 = p[0] - p[2];
  const Vec3 normal = cross(edge0, edge1);  // = (p1 - p0) x (p2 - p0)
  s.normal_squared = squared_norm(normal);
  s.edge_squared = squared_norm(edge0);
  const double edge_length = std::sqrt(s.edge_squared);
  // Reciprocals: one division per normalised vector.
  s.t = (1.0 / edge_length) * edge0;
  s.face_normal = (1.0 / std::sqrt(s.normal_squared)) * normal;
  const Vec3 b = cross(s.face_normal, s.t);
  // Edge and normal-difference coordinates (u, v) and (dnu, dnv) in the frame (t, b). Edge 0 is
  // t's own edge, and edges and normal differences both sum to zero around the face, so two
  // edges give all three.
  const Vec3 dn0 = n[2] - n[1], dn1 = n[0] - n[2];
  const double u1 = dot(edge1, s.t), v1 = dot(edge1, b);
  const double u[3] = {edge_length, u1, -edge_length - u1}, v[3] = {0, v1, -v1};
  const double dnu0 = dot(dn0, s.t), dnu1 = dot(dn1, s.t), dnv0 = dot(dn0, b), dnv1 = dot(dn1, b);
  const double dnu[3] = {dnu0, dnu1, -dnu0 - dnu1}, dnv[3] = {dnv0, dnv1, -dnv0 - dnv1};
  // Normal equations of the rows (u, v, 0) . (e, f, g) = dnu and (0, u, v) . (e, f, g) = dnv.
  s.uu = s.uv = s.vv = s.r0 = s.r1 = s.r2 = 0;
#pragma GCC unroll 3
  for (int k = 0; k < 3; ++k) {
    s.uu += u[k] * u[k];
    s.uv += u[k] * v[k];
    s.vv += v[k] * v[k];
    s.r0 += u[k] * dnu[k];
    s.r1 += v[k] * dnu[k] + u[k] * dnv[k];
    s.r2 += v[k] * dnv[k];
  }
  return s;
}

// Pass 2 for one face: the fit of fit_system, solved with Eigen, then its transport to each
// corner's vertex frame.
// Returns a bit per corner left out of its vertex's average (degenerate, failed or folded).
std::uint8_t fit_and_transport(const Vertices& V, const Faces& F, const Vertices& N, Index face, FaceRecord& record) {
  const double area[3] = {record.geometry.area[0], record.geometry.area[1], record.geometry.area[2]};
  record.corner[0] = record.corner[1] = record.corner[2] = Tensor{0, 0, 0};  // now the active member
  const Index* corner = face_row(F, face);
  const Vec3 p[3] = {row(V, corner[0]), row(V, corner[1]), row(V, corner[2])};
  const Vec3 n[3] = {row(N, corner[0]), row(N, corner[1]), row(N, corner[2])};
  const FitSystem system = fit_system(p, n);
  const std::uint8_t all_left_out = (area[0] > 0 ? 1 : 0) | (area[1] > 0 ? 2 : 0) | (area[2] > 0 ? 4 : 0);
  if (!(system.normal_squared > 0) || !(system.edge_squared > 0)) return all_left_out;
  const auto& [t, face_normal, normal_squared, edge_squared, uu, uv, vv, r0, r1, r2] = system;
  Eigen::Matrix3d normal_matrix;
  normal_matrix << uu, uv, 0, uv, uu + vv, uv, 0, uv, vv;
  const Eigen::Vector3d rhs(r0, r1, r2);
  // A small solve from Eigen, not the widely copied hand-written 3x3 LDLT (which reads entries
  // before writing them and biases curvatures low). The matrix is symmetric positive definite
  // with determinant (uu + vv)(uu vv - uv^2) = 12 area^2 (sum of squared edge lengths) > 0 for
  // any non-degenerate triangle, so Eigen's closed-form 3x3 inverse (cofactors) is accurate and
  // about 5x cheaper than its LLT here; pivoted LDLT takes over if rounding leaves no positive,
  // finite determinant (needle triangles).
  Eigen::Matrix3d inverse;
  double determinant = 0;
  bool invertible = false;
  normal_matrix.computeInverseAndDetWithCheck(inverse, determinant, invertible, 0.0);
  const Eigen::Vector3d solution = invertible && determinant > 0 && std::isfinite(determinant)
                                       ? Eigen::Vector3d(inverse * rhs)
                                       : Eigen::Vector3d(normal_matrix.ldlt().solve(rhs));
  if (!solution.allFinite()) return all_left_out;
  const double e = solution[0], f = solution[1], g = solution[2];

  std::uint8_t left_out = 0;
  for (int k = 0; k < 3; ++k) {
    if (!(area[k] > 0)) continue;
    if (dot(face_normal, n[k]) <= kFoldedCosine) {
      left_out |= static_cast<std::uint8_t>(1 << k);
      continue;
    }
    const Tensor tensor = transport_tensor(e, f, g, t, face_normal, n[k], vertex_frame(n[k]));
    record.corner[k] = {area[k] * tensor.ku, area[k] * tensor.kuv, area[k] * tensor.kv};
  }
  return left_out;
}

// Pass 2 for the faces [first, first + count), count <= kBlock: fit_and_transport's
// arithmetic on a block of faces at once, as loops over lanes of structure-of-arrays buffers
// that the compiler vectorises (VERTEXFLOW_SIMD_CLONES). This pass is most of the estimator's
// arithmetic; vectorised it ran 3x faster (1M vertices: 295 -> 95 ms on one thread). Faces it
// does not handle (degenerate, or a normal matrix without a positive, finite determinant) go
// through fit_and_transport.
//
// The 3x3 solve is written out here because Eigen's fixed-size solvers do not run across SIMD
// lanes. It is the cofactor inverse that Eigen's closed-form 3x3 inverse also uses, specialised
// to this matrix [[a, b, 0], [b, a + c, b], [0, b, c]], whose determinant factors as
// (a + c)(ac - b^2) = (sum of squared edge lengths) 12 area^2.
VERTEXFLOW_SIMD_CLONES
void fit_and_transport_block(const Vertices& V, const Faces& F, const Vertices& N, Index first, int count,
                             FaceRecord* records, std::uint8_t* left_out) {
  constexpr int L = kBlock;
  // [corner][coordinate][lane]
  alignas(64) double p[3][3][L], n[3][3][L], out[3][3][L];
  alignas(64) double area[3][L], folded[3][L], handled[L];
  for (int i = 0; i < L; ++i) {
    const Index f = first + (i < count ? i : count - 1);
    const Index* face = face_row(F, f);
    const FaceGeometry& g = records[f].geometry;
    for (int k = 0; k < 3; ++k) {
      const double* pk = V.data() + 3 * static_cast<std::ptrdiff_t>(face[k]);
      const double* nk = N.data() + 3 * static_cast<std::ptrdiff_t>(face[k]);
      for (int d = 0; d < 3; ++d) {
        p[k][d][i] = pk[d];
        n[k][d][i] = nk[d];
      }
      area[k][i] = g.area[k];
    }
  }

  for (int i = 0; i < L; ++i) {
    const Vec3 pv[3] = {{p[0][0][i], p[0][1][i], p[0][2][i]},
                        {p[1][0][i], p[1][1][i], p[1][2][i]},
                        {p[2][0][i], p[2][1][i], p[2][2][i]}};
    const Vec3 nv[3] = {{n[0][0][i], n[0][1][i], n[0][2][i]},
                        {n[1][0][i], n[1][1][i], n[1][2][i]},
                        {n[2][0][i], n[2][1][i], n[2][2][i]}};
    const auto [t, face_normal, normal_squared, edge_squared, uu, uv, vv, r0, r1, r2] = fit_system(pv, nv);
    // Cofactor solve of [[uu, uv, 0], [uv, uu + vv, uv], [0, uv, vv]] (e, f, g) = (r0, r1, r2).
    const double trace = uu + vv, gram = uu * vv - uv * uv;
    const double determinant = trace * gram;
    const double inverse = 1.0 / determinant;
    const double e = ((trace * vv - uv * uv) * r0 - uv * vv * r1 + uv * uv * r2) * inverse;
    const double f = (-uv * vv * r0 + uu * vv * r1 - uu * uv * r2) * inverse;
    const double g = (uv * uv * r0 - uu * uv * r1 + (uu * trace - uv * uv) * r2) * inverse;
    // Flags as 0/1 doubles and blends instead of branches keep this loop vectorisable.
    handled[i] = static_cast<double>((normal_squared > 0) & (edge_squared > 0) & (determinant > 0) &
                                     (determinant <= std::numeric_limits<double>::max()));

#pragma GCC unroll 3
    for (int k = 0; k < 3; ++k) {
      const double cosine = dot(face_normal, nv[k]);
      const double counted = static_cast<double>(area[k][i] > 0);
      const double kept = counted * static_cast<double>(cosine > kFoldedCosine);
      folded[k][i] = counted - kept;
      const Frame frame = vertex_frame(nv[k]);
      // Folded corners divide by 2 - 1e-9 or so instead of ~0: finite, and then multiplied by 0.
      const double scale = dot(nv[k], t) / (1.0 + cosine + (1.0 - kept));
      const Vec3 moved = t - scale * (face_normal + nv[k]);
      const Tensor tensor = rotate_tensor(e, f, g, dot(frame.u, moved), dot(frame.w, moved));
      const double weight = kept * area[k][i];
      out[k][0][i] = weight * tensor.ku;
      out[k][1][i] = weight * tensor.kuv;
      out[k][2][i] = weight * tensor.kv;
    }
  }

  for (int i = 0; i < count; ++i) {
    const Index f = first + i;
    if (handled[i] == 0.0) {
      left_out[f] = fit_and_transport(V, F, N, f, records[f]);
      continue;
    }
    for (int k = 0; k < 3; ++k) records[f].corner[k] = Tensor{out[k][0][i], out[k][1][i], out[k][2][i]};
    left_out[f] = static_cast<std::uint8_t>((folded[0][i] != 0.0 ? 1 : 0) | (folded[1][i] != 0.0 ? 2 : 0) |
                                            (folded[2][i] != 0.0 ? 4 : 0));
  }
}

// Pass 3 for the vertices [first, first + count), count <= kBlock: diagonalises each vertex's
// tensor (ku, kuv, kv) in its frame (vertex_frame) into k1 >= k2 and T1, T2 (T1 x T2 = N), as
// a branch-free loop over lanes (VERTEXFLOW_SIMD_CLONES).
VERTEXFLOW_SIMD_CLONES
void diagonalize_block(const Tensor* tensor, Index first, int count, Curvature& c) {
  constexpr int L = kBlock;
  alignas(64) double ku[L], kuv[L], kv[L], n[3][L], k1[L], k2[L], t1[3][L], t2[3][L];
  for (int i = 0; i < L; ++i) {
    const int j = i < count ? i : count - 1;
    ku[i] = tensor[j].ku;
    kuv[i] = tensor[j].kuv;
    kv[i] = tensor[j].kv;
    const Vec3 normal = row(c.N, first + j);
    n[0][i] = normal.x;
    n[1][i] = normal.y;
    n[2][i] = normal.z;
  }
  for (int i = 0; i < L; ++i) {
    const Vec3 normal{n[0][i], n[1][i], n[2][i]};
    const Frame frame = vertex_frame(normal);
    const double mean = 0.5 * (ku[i] + kv[i]);
    const double half_difference = 0.5 * (ku[i] - kv[i]);
    // Plain square roots: the operands are curvatures of a mesh whose size read_mesh bounds,
    // far from overflow, and std::hypot's care costs more than the rest of this loop.
    const double radius = std::sqrt(half_difference * half_difference + kuv[i] * kuv[i]);
    k1[i] = mean + radius;
    k2[i] = mean - radius;
    // Eigenvector of k1 in (u, w) coordinates: (radius + half_difference, kuv), or the
    // equivalent (kuv, radius - half_difference), whichever is better conditioned.
    const double swap = static_cast<double>(half_difference < 0), keep = 1.0 - swap;
    // At an umbilic both are 0 and any direction will do: the tiny shift of x then makes T1 = u
    // (and changes nothing elsewhere), without a branch.
    constexpr double kTiny = 1e-300;
    const double x = keep * (radius + half_difference) + swap * kuv[i] + kTiny;
    const double y = keep * kuv[i] + swap * (radius - half_difference);
    const double inverse = 1.0 / (std::sqrt(x * x + y * y) + kTiny);
    const Vec3 d1 = (x * inverse) * frame.u + (y * inverse) * frame.w;
    const Vec3 d2 = cross(normal, d1);
    t1[0][i] = d1.x;
    t1[1][i] = d1.y;
    t1[2][i] = d1.z;
    t2[0][i] = d2.x;
    t2[1][i] = d2.y;
    t2[2][i] = d2.z;
  }
  for (int i = 0; i < count; ++i) {
    const Index v = first + i;
    c.k1[v] = k1[i];
    c.k2[v] = k2[i];
    set_row(c.T1, v, {t1[0][i], t1[1][i], t1[2][i]});
    set_row(c.T2, v, {t2[0][i], t2[1][i], t2[2][i]});
  }
}

}  // namespace

Vertices vertex_normals(const Vertices& V, const Faces& F, NormalWeighting weighting) {
  Vertices N = Vertices::Zero(V.rows(), 3);
  for (Index f = 0; f < F.rows(); ++f) {
    const FaceGeometry g = face_geometry(V, F, f, weighting);
    for (int k = 0; k < 3; ++k) set_row(N, F(f, k), row(N, F(f, k)) + g.weight[k] * g.normal);
  }
  for (Index v = 0; v < V.rows(); ++v) {
    const double length = N.row(v).norm();
    N.row(v) = length > 0 ? Eigen::RowVector3d(N.row(v) / length) : Eigen::RowVector3d(0, 0, 1);
  }
  return N;
}

CornerAreas corner_areas(const Vertices& V, const Faces& F) {
  CornerAreas areas(F.rows(), 3);
  parallel_range(static_cast<Index>(F.rows()), [&](Index f) {
    const FaceGeometry g = face_geometry(V, F, f, NormalWeighting::Area);
    for (int k = 0; k < 3; ++k) areas(f, k) = g.area[k];
  });
  return areas;
}

Eigen::VectorXd vertex_areas(const Vertices& V, const Faces& F) {
  const CornerAreas corners = corner_areas(V, F);
  Eigen::VectorXd areas = Eigen::VectorXd::Zero(V.rows());
  for (Index f = 0; f < F.rows(); ++f) {
    for (int k = 0; k < 3; ++k) areas[F(f, k)] += corners(f, k);
  }
  return areas;
}

namespace {

// A non-manifold or inconsistently oriented mesh (curvature.h): the estimator runs on the
// manifold split (manifold_split.h); a vertex takes the values of its copy with the largest
// area (the fan that holds most of its neighbourhood) and the area of all its copies, so the
// areas still sum to the surface's.
Curvature curvature_of_manifold_split(const Vertices& V, const Faces& F, const Topology& topology,
                                      const CurvatureOptions& options) {
  const ManifoldSplit split = split_non_manifold(V, F, topology);
  const Curvature on_copies = principal_curvatures(split.V, split.F, build_topology(split.F, split.V.rows()), options);
  const Index nv = static_cast<Index>(V.rows());
  std::vector<Index> largest(static_cast<std::size_t>(nv));
  Curvature c;
  c.area.resize(nv);
  for (Index v = 0; v < nv; ++v) {
    const Index first = split.first_copy[static_cast<std::size_t>(v)],
                last = split.first_copy[static_cast<std::size_t>(v) + 1];
    Index best = first;
    double area = 0;
    for (Index s = first; s < last; ++s) {
      area += on_copies.area[s];
      if (on_copies.area[s] > on_copies.area[best]) best = s;
    }
    largest[static_cast<std::size_t>(v)] = best;
    c.area[v] = area;
  }
  c.k1 = on_copies.k1(largest);
  c.k2 = on_copies.k2(largest);
  c.T1 = on_copies.T1(largest, Eigen::all);
  c.T2 = on_copies.T2(largest, Eigen::all);
  c.N = on_copies.N(largest, Eigen::all);
  return c;
}

}  // namespace

Curvature principal_curvatures(const Vertices& V, const Faces& F, const CurvatureOptions& options) {
  return principal_curvatures(V, F, build_topology(F, static_cast<Index>(V.rows())), options);
}

Curvature principal_curvatures(const Vertices& V, const Faces& F, const Topology& topology,
                               const CurvatureOptions& options) {
  const Index nv = static_cast<Index>(V.rows());
  const Index nf = static_cast<Index>(F.rows());
  if (topology.num_vertices != nv || topology.num_faces != nf)
    throw std::invalid_argument("principal_curvatures: the topology was built for another mesh");
  if (!topology.is_manifold() || !topology.is_oriented) return curvature_of_manifold_split(V, F, topology, options);
  Curvature c;
  c.k1.resize(nv);
  c.k2.resize(nv);
  c.T1.resize(nv, 3);
  c.T2.resize(nv, 3);
  c.N.resize(nv, 3);
  c.area.resize(nv);
  for (Eigen::VectorXd* v : {&c.k1, &c.k2, &c.area}) advise_huge_pages(*v);
  for (Vertices* m : {&c.T1, &c.T2, &c.N}) advise_huge_pages(*m);

  // One record per face (FaceRecord), uninitialised on purpose: pass 1 writes every one.
  const std::unique_ptr<FaceRecord[]> records(new FaceRecord[static_cast<std::size_t>(nf)]);
  advise_huge_pages(records.get(), static_cast<std::size_t>(nf) * sizeof(FaceRecord));
  const std::unique_ptr<std::uint8_t[]> left_out(new std::uint8_t[static_cast<std::size_t>(nf)]);
  auto record = [&](Index f) -> FaceRecord& { return records[static_cast<std::size_t>(f)]; };
  auto incident_faces = [&](Index v) {
    const auto first = static_cast<std::size_t>(topology.face_offsets[static_cast<std::size_t>(v)]);
    const auto last = static_cast<std::size_t>(topology.face_offsets[static_cast<std::size_t>(v) + 1]);
    return std::pair(topology.vertex_faces.data() + first, topology.vertex_faces.data() + last);
  };

  // Pass 1, per face: normal weights and mixed areas of the corners.
  if (options.normal_weighting == NormalWeighting::Angle) {  // atan2 does not vectorise
    parallel_range(nf, [&](Index f) { record(f).geometry = face_geometry(V, F, f, options.normal_weighting); });
  } else {
    parallel_blocks(nf, [&](Index first, int count) {
      face_geometry_block(V, F, first, count, options.normal_weighting == NormalWeighting::Max1999, records.get());
    });
  }

  // Pass 1b, per vertex: unit normal and mixed area, summed over the incident faces in the
  // topology's fixed order.
  parallel_range(nv, [&](Index v) {
    Vec3 normal{0, 0, 0};
    double area = 0;
    const auto [begin, end] = incident_faces(v);
    for (const Index* f = begin; f != end; ++f) {
      const FaceGeometry& g = record(*f).geometry;
      const int k = corner_of(F, *f, v);
      normal = normal + g.weight[k] * g.normal;
      area += g.area[k];
    }
    const double length = std::sqrt(squared_norm(normal));
    set_row(c.N, v, length > 0 ? (1.0 / length) * normal : Vec3{0, 0, 1});
    c.area[v] = area;
  });

  // Pass 2, per face: fit and transport (fit_and_transport_block).
  parallel_blocks(nf, [&](Index first, int count) {
    fit_and_transport_block(V, F, c.N, first, count, records.get(), left_out.get());
  });

  // Pass 3, per vertex: the area-weighted mean of its corners' tensors (Rusinkiewicz 2004,
  // section 4), then (unless the tensors are smoothed first) principal curvatures and
  // directions. Corners left out by pass 2 (rare) have their area taken off the weight.
  auto vertex_tensor = [&](Index v) {
    double ku = 0, kuv = 0, kv = 0, weight = c.area[v];
    const auto [begin, end] = incident_faces(v);
    for (const Index* f = begin; f != end; ++f) {
      const int k = corner_of(F, *f, v);
      const Tensor& t = record(*f).corner[k];
      ku += t.ku;
      kuv += t.kuv;
      kv += t.kv;
      if (left_out[static_cast<std::size_t>(*f)] & (1 << k))
        weight -= face_geometry(V, F, *f, NormalWeighting::Area).area[k];  // areas do not depend on it
    }
    if (!(weight > 0)) return Tensor{0, 0, 0};
    const double inverse = 1.0 / weight;
    return Tensor{ku * inverse, kuv * inverse, kv * inverse};
  };
  if (options.smoothing_rounds <= 0) {
    parallel_blocks(nv, [&](Index first, int count) {
      Tensor tensor[kBlock];
      for (int i = 0; i < count; ++i) tensor[i] = vertex_tensor(first + i);
      diagonalize_block(tensor, first, count, c);
    });
    return c;
  }

  // Optional smoothing: average each tensor with its neighbours', transported likewise.
  std::vector<Tensor> tensor(static_cast<std::size_t>(nv));
  parallel_range(nv, [&](Index v) { tensor[static_cast<std::size_t>(v)] = vertex_tensor(v); });
  for (int round = 0; round < options.smoothing_rounds; ++round) {
    std::vector<Tensor> smoothed(static_cast<std::size_t>(nv));
    parallel_range(nv, [&](Index v) {
      const Vec3 n = row(c.N, v);
      const Frame frame = vertex_frame(n);
      const Tensor& own = tensor[static_cast<std::size_t>(v)];
      double weight = c.area[v];
      Tensor sum{weight * own.ku, weight * own.kuv, weight * own.kv};
      const auto [begin, end] = topology.ring(v);
      for (const Index* j = begin; j != end; ++j) {
        const Vec3 nj = row(c.N, *j);
        if (dot(nj, n) <= kFoldedCosine) continue;
        // The neighbour's tensor is given in its frame (uj, nj x uj).
        const Tensor& tj = tensor[static_cast<std::size_t>(*j)];
        const Tensor moved = transport_tensor(tj.ku, tj.kuv, tj.kv, vertex_frame(nj).u, nj, n, frame);
        const double aj = c.area[*j];
        sum = {sum.ku + aj * moved.ku, sum.kuv + aj * moved.kuv, sum.kv + aj * moved.kv};
        weight += aj;
      }
      smoothed[static_cast<std::size_t>(v)] =
          weight > 0 ? Tensor{sum.ku / weight, sum.kuv / weight, sum.kv / weight} : own;
    });
    tensor = std::move(smoothed);
  }
  parallel_blocks(nv, [&](Index first, int count) {
    diagonalize_block(&tensor[static_cast<std::size_t>(first)], first, count, c);
  });
  return c;
}

}  // namespace vertexflow
