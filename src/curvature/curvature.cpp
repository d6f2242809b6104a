// Rusinkiewicz (2004) curvature estimation; see include/vertexflow/curvature.h for the
// conventions. Every pass is either "per face, write own slots" or "per vertex, gather from
// incident faces in the topology's fixed order", so results do not depend on thread count.
#include "vertexflow/curvature.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Eigen/Dense>

#include <cmath>
#include <stdexcept>

namespace vertexflow {
namespace {

using CornerAreas = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;

template <class Body>
void parallel_range(Index n, Body&& body) {
  tbb::parallel_for(tbb::blocked_range<Index>(0, n, 2048), [&](const tbb::blocked_range<Index>& r) {
    for (Index i = r.begin(); i != r.end(); ++i) body(i);
  });
}

Eigen::Vector3d position(const Vertices& V, Index v) {
  return V.row(v).transpose();
}

// Per-face quantities: the (unnormalised) face normal n = (p1 - p0) x (p2 - p0), each
// corner's weight in its vertex normal (the cross product of the two edges at every corner is
// n, so a corner contributes weight * n), and each corner's mixed area (Meyer et al. 2003).
struct FaceGeometry {
  Eigen::Vector3d normal;
  Eigen::Vector3d normal_weight;
  Eigen::Vector3d corner_area;
};

// One pass over the face's three edge vectors d_k = p_{k+1} - p_k: at corner k the edges are
// d_k and -d_{k+2}, so their dot product and squared lengths come from these three vectors, and
// each weight or area needs no division of its own (this runs once per corner per vertex).
FaceGeometry face_geometry(const Vertices& V, const Faces& F, Index f, NormalWeighting weighting) {
  const Eigen::Vector3d p[3] = {position(V, F(f, 0)), position(V, F(f, 1)), position(V, F(f, 2))};
  const Eigen::Vector3d d[3] = {p[1] - p[0], p[2] - p[1], p[0] - p[2]};
  FaceGeometry g;
  g.normal = d[0].cross(-d[2]);
  g.normal_weight.setZero();
  g.corner_area.setZero();
  const double length = g.normal.norm();
  if (!(length > 0)) return g;
  const double squared[3] = {d[0].squaredNorm(), d[1].squaredNorm(), d[2].squaredNorm()};
  double dot[3];  // of the two edges at each corner; negative = obtuse
  for (int k = 0; k < 3; ++k) dot[k] = -d[k].dot(d[(k + 2) % 3]);

  switch (weighting) {
    case NormalWeighting::Max1999: {
      // 1 / (|d_k|^2 |d_{k+2}|^2) = |d_{k+1}|^2 / (product of all three).
      const double inverse = 1.0 / (squared[0] * squared[1] * squared[2]);
      for (int k = 0; k < 3; ++k) g.normal_weight[k] = squared[(k + 1) % 3] * inverse;
      break;
    }
    case NormalWeighting::Area:
      g.normal_weight.setOnes();
      break;
    case NormalWeighting::Angle:
      for (int k = 0; k < 3; ++k) g.normal_weight[k] = std::atan2(length, dot[k]) / length;
      break;
  }

  const double area = 0.5 * length;
  for (int k = 0; k < 3; ++k) {
    if (dot[k] < 0) {  // obtuse at k: half to k, a quarter to each other corner
      g.corner_area.setConstant(0.25 * area);
      g.corner_area[k] = 0.5 * area;
      return g;
    }
  }
  // Voronoi region of corner k: (|p_k p_j|^2 cot(angle at l) + |p_k p_l|^2 cot(angle at j)) / 8
  // with j = k + 1, l = k + 2 and cot(angle at m) = dot[m] / (2 area).
  const double inverse = 1.0 / (16.0 * area);
  for (int k = 0; k < 3; ++k) {
    const int j = (k + 1) % 3, l = (k + 2) % 3;
    g.corner_area[k] = (squared[k] * dot[l] + squared[l] * dot[j]) * inverse;
  }
  return g;
}

// The second fundamental form of one face, [[e, f], [f, g]] in the face's frame (t, n x t),
// with n the unit face normal. A zero normal marks a degenerate face.
struct FaceTensor {
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  Eigen::Vector3d n = Eigen::Vector3d::Zero();
  double e = 0, f = 0, g = 0;
};

// Least-squares fit (Rusinkiewicz 2004, section 3): for each edge E (from corner j to corner
// l), II * (E.t, E.b) = ((N_l - N_j).t, (N_l - N_j).b). Six equations, three unknowns.
FaceTensor fit_face_tensor(const Vertices& V, const Faces& F, const Vertices& N, Index face) {
  FaceTensor ft;
  const Eigen::Vector3d p[3] = {position(V, F(face, 0)), position(V, F(face, 1)), position(V, F(face, 2))};
  const Eigen::Vector3d normal = (p[1] - p[0]).cross(p[2] - p[0]);
  const double edge = (p[2] - p[1]).norm();
  if (!(normal.norm() > 0) || !(edge > 0)) return ft;
  // Reciprocals: one division instead of three per normalised vector (this is the hot loop).
  ft.t = (p[2] - p[1]) * (1.0 / edge);
  const Eigen::Vector3d unit_normal = normal * (1.0 / normal.norm());
  const Eigen::Vector3d b = unit_normal.cross(ft.t);
  // Normal equations of the rows (u, v, 0) . (e, f, g) = dN.t and (0, u, v) . (e, f, g) = dN.b,
  // accumulated directly rather than through a 6 x 3 matrix.
  double uu = 0, uv = 0, vv = 0;
  Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
  for (int k = 0; k < 3; ++k) {
    const int j = (k + 1) % 3, l = (k + 2) % 3;
    const Eigen::Vector3d E = p[l] - p[j];
    const Eigen::Vector3d dN = N.row(F(face, l)).transpose() - N.row(F(face, j)).transpose();
    const double u = E.dot(ft.t), v = E.dot(b);
    const double dnu = dN.dot(ft.t), dnv = dN.dot(b);
    uu += u * u;
    uv += u * v;
    vv += v * v;
    rhs += Eigen::Vector3d(u * dnu, v * dnu + u * dnv, v * dnv);
  }
  Eigen::Matrix3d normal_matrix;
  normal_matrix << uu, uv, 0, uv, uu + vv, uv, 0, uv, vv;
  // A robust small solve from Eigen, not the widely copied hand-written 3x3 LDLT (which reads
  // entries before writing them and biases curvatures low). The matrix is symmetric positive
  // definite for any non-degenerate triangle, so Cholesky applies; pivoted LDLT takes over if
  // rounding makes it fail (needle triangles).
  Eigen::Vector3d solution;
  const Eigen::LLT<Eigen::Matrix3d> llt(normal_matrix);
  if (llt.info() == Eigen::Success) {
    solution = llt.solve(rhs);
  } else {
    solution = normal_matrix.ldlt().solve(rhs);
  }
  if (!solution.allFinite()) return ft;
  ft.e = solution[0];
  ft.f = solution[1];
  ft.g = solution[2];
  ft.n = unit_normal;
  return ft;
}

// The first axis of a vertex's tangent frame (u, N x u, N): any unit vector orthogonal to N,
// chosen from N alone so every pass derives the same frame without storing it.
Eigen::Vector3d vertex_frame(const Eigen::Vector3d& n) {
  return n.unitOrthogonal();
}

// Rotates a vector x tangent to unit `from` (x . from = 0) by the smallest rotation taking
// `from` to unit `to`. Rodrigues' R x = x + w x x + w x (w x x) / (1 + c), with w = from x to and
// c = from . to, reduces for such x to x - (to . x) (from + to) / (1 + c): one dot product
// instead of three cross products (this runs once per corner).
inline Eigen::Vector3d rotate_tangent(const Eigen::Vector3d& x, const Eigen::Vector3d& from,
                                      const Eigen::Vector3d& to) {
  return x - (to.dot(x) / (1.0 + from.dot(to))) * (from + to);
}

// The symmetric tensor (ku, kuv, kv) in the vertex frame (u, w = N x u) of a tensor
// [[e, f], [f, g]] given in the frame (t, N x t) of the same tangent plane. With
// cos(phi) = u.t and sin(phi) = w.t, the frame change is a plane rotation by phi.
inline Eigen::Vector3d tensor_in_frame(double e, double f, double g, const Eigen::Vector3d& t, const Eigen::Vector3d& u,
                                       const Eigen::Vector3d& w) {
  const double c = u.dot(t), s = w.dot(t);
  // u = c t - s b and w = s t + c b, where b = N x t.
  const double u1 = c, v1 = -s, u2 = s, v2 = c;
  return {e * u1 * u1 + 2 * f * u1 * v1 + g * v1 * v1, e * u1 * u2 + f * (u1 * v2 + u2 * v1) + g * v1 * v2,
          e * u2 * u2 + 2 * f * u2 * v2 + g * v2 * v2};
}

// Faces whose normal is within this of the opposite of the vertex normal are folded over; their
// frame cannot be rotated meaningfully and they are left out of that vertex's average.
constexpr double kFoldedCosine = -1.0 + 1e-9;

// Diagonalises the vertex tensor into k1 >= k2 and T1, T2 (T1 x T2 = N).
void diagonalize(const Eigen::Vector3d& tensor, const Eigen::Vector3d& u, const Eigen::Vector3d& v,
                 const Eigen::Vector3d& n, double& k1, double& k2, Eigen::Vector3d& t1, Eigen::Vector3d& t2) {
  const double ku = tensor[0], kuv = tensor[1], kv = tensor[2];
  const double mean = 0.5 * (ku + kv);
  const double half_difference = 0.5 * (ku - kv);
  // Plain square roots: the operands are curvatures of a mesh whose size read_mesh bounds, far
  // from overflow, and std::hypot's care costs more than the rest of this function.
  const double radius = std::sqrt(half_difference * half_difference + kuv * kuv);
  k1 = mean + radius;
  k2 = mean - radius;
  // Eigenvector of k1 in (u, v) coordinates: (radius + half_difference, kuv), or the
  // equivalent (kuv, radius - half_difference) when that is better conditioned.
  double x = radius + half_difference, y = kuv;
  if (half_difference < 0) x = kuv, y = radius - half_difference;
  const double length = std::sqrt(x * x + y * y);
  if (length > 0) {
    const double inverse = 1.0 / length;
    t1 = (x * inverse) * u + (y * inverse) * v;
  } else {  // umbilic: any direction
    t1 = u;
  }
  t2 = n.cross(t1);
}

}  // namespace

Vertices vertex_normals(const Vertices& V, const Faces& F, NormalWeighting weighting) {
  Vertices N = Vertices::Zero(V.rows(), 3);
  for (Index f = 0; f < F.rows(); ++f) {
    const FaceGeometry g = face_geometry(V, F, f, weighting);
    for (int k = 0; k < 3; ++k) N.row(F(f, k)) += g.normal_weight[k] * g.normal.transpose();
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
    areas.row(f) = face_geometry(V, F, f, NormalWeighting::Area).corner_area.transpose();
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

Curvature principal_curvatures(const Vertices& V, const Faces& F, const CurvatureOptions& options) {
  return principal_curvatures(V, F, build_topology(F, static_cast<Index>(V.rows())), options);
}

Curvature principal_curvatures(const Vertices& V, const Faces& F, const Topology& topology,
                               const CurvatureOptions& options) {
  const Index nv = static_cast<Index>(V.rows());
  const Index nf = static_cast<Index>(F.rows());
  if (topology.num_vertices != nv || topology.num_faces != nf)
    throw std::invalid_argument("principal_curvatures: the topology was built for another mesh");
  if (!topology.is_manifold()) throw std::invalid_argument(describe_non_manifold(topology));
  Curvature c;
  c.k1 = Eigen::VectorXd::Zero(nv);
  c.k2 = Eigen::VectorXd::Zero(nv);
  c.T1.resize(nv, 3);
  c.T2.resize(nv, 3);
  c.N.resize(nv, 3);
  c.area = Eigen::VectorXd::Zero(nv);

  auto corner_of = [&](Index f, Index v) { return F(f, 0) == v ? 0 : F(f, 1) == v ? 1 : 2; };
  // The record slots of v's corners, in the topology's fixed face order (determinism).
  auto sum_corner_records = [&](Index v, const std::vector<Eigen::Vector4d>& records) {
    Eigen::Vector4d sum = Eigen::Vector4d::Zero();
    const auto first = topology.face_offsets[static_cast<std::size_t>(v)];
    const auto last = topology.face_offsets[static_cast<std::size_t>(v) + 1];
    for (Index i = first; i < last; ++i) {
      const Index f = topology.vertex_faces[static_cast<std::size_t>(i)];
      sum += records[3 * static_cast<std::size_t>(f) + static_cast<std::size_t>(corner_of(f, v))];
    }
    return sum;
  };

  // One record per corner, reused by both gathers: first (weighted face normal, mixed area),
  // then (area-weighted tensor in the vertex frame, area). Each face's geometry is computed
  // once and each vertex sums its corners, which is cheaper than recomputing per corner and
  // keeps the order of additions fixed.
  std::vector<Eigen::Vector4d> corner_record(3 * static_cast<std::size_t>(nf));
  auto record = [&](Index f, int k) -> Eigen::Vector4d& {
    return corner_record[3 * static_cast<std::size_t>(f) + static_cast<std::size_t>(k)];
  };

  // Pass 1, per face: each corner's contribution to its vertex normal and mixed area.
  parallel_range(nf, [&](Index f) {
    const FaceGeometry g = face_geometry(V, F, f, options.normal_weighting);
    for (int k = 0; k < 3; ++k) record(f, k) << g.normal_weight[k] * g.normal, g.corner_area[k];
  });

  // Pass 2, per vertex: unit normal, mixed area and the first axis of the tangent frame.
  Vertices frame_u(nv, 3);
  parallel_range(nv, [&](Index v) {
    const Eigen::Vector4d sum = sum_corner_records(v, corner_record);
    const double length = sum.head<3>().norm();
    const Eigen::Vector3d n = length > 0 ? Eigen::Vector3d(sum.head<3>() * (1.0 / length)) : Eigen::Vector3d(0, 0, 1);
    c.N.row(v) = n.transpose();
    frame_u.row(v) = vertex_frame(n).transpose();
    c.area[v] = sum[3];
  });

  // Pass 3, per face: fit the second fundamental form (Rusinkiewicz 2004, section 3) and
  // rotate it into the tangent frame of each of its three vertices (section 4).
  parallel_range(nf, [&](Index f) {
    const FaceTensor ft = fit_face_tensor(V, F, c.N, f);
    for (int k = 0; k < 3; ++k) {
      Eigen::Vector4d& slot = record(f, k);
      const double corner_area = slot[3];
      const Index v = F(f, k);
      const Eigen::Vector3d n = c.N.row(v).transpose();
      // Skip degenerate faces (zero area or failed fit: zero normal) and folded-over ones.
      if (!(corner_area > 0) || ft.n.squaredNorm() == 0 || ft.n.dot(n) <= kFoldedCosine) {
        slot.setZero();
        continue;
      }
      const Eigen::Vector3d u = frame_u.row(v).transpose();
      const Eigen::Vector3d t = rotate_tangent(ft.t, ft.n, n);
      slot << corner_area * tensor_in_frame(ft.e, ft.f, ft.g, t, u, n.cross(u)), corner_area;
    }
  });

  // Pass 4, per vertex: the area-weighted mean of its corners' tensors, then (unless the
  // tensors are smoothed first) principal curvatures and directions.
  Vertices tensor = Vertices::Zero(nv, 3);
  auto diagonalize_vertex = [&](Index v) {
    const Eigen::Vector3d n = c.N.row(v).transpose(), u = frame_u.row(v).transpose(), w = n.cross(u);
    double k1 = 0, k2 = 0;
    Eigen::Vector3d t1, t2;
    diagonalize(tensor.row(v).transpose(), u, w, n, k1, k2, t1, t2);
    c.k1[v] = k1;
    c.k2[v] = k2;
    c.T1.row(v) = t1.transpose();
    c.T2.row(v) = t2.transpose();
  };
  const bool smooth = options.smoothing_rounds > 0;
  parallel_range(nv, [&](Index v) {
    const Eigen::Vector4d sum = sum_corner_records(v, corner_record);
    if (sum[3] > 0) tensor.row(v) = sum.head<3>().transpose() * (1.0 / sum[3]);
    if (!smooth) diagonalize_vertex(v);
  });
  corner_record = std::vector<Eigen::Vector4d>();
  if (!smooth) return c;

  // Optional smoothing: average each tensor with its neighbours', transported likewise.
  for (int round = 0; round < options.smoothing_rounds; ++round) {
    Vertices smoothed(nv, 3);
    parallel_range(nv, [&](Index v) {
      const Eigen::Vector3d n = c.N.row(v).transpose(), u = frame_u.row(v).transpose(), w = n.cross(u);
      Eigen::Vector3d sum = c.area[v] * tensor.row(v).transpose();
      double weight = c.area[v];
      const auto [begin, end] = topology.ring(v);
      for (const Index* j = begin; j != end; ++j) {
        const Eigen::Vector3d nj = c.N.row(*j).transpose();
        if (nj.dot(n) <= kFoldedCosine) continue;
        const Eigen::Vector3d uj = rotate_tangent(frame_u.row(*j).transpose(), nj, n);
        const Eigen::Vector3d tj = tensor.row(*j).transpose();
        sum += c.area[*j] * tensor_in_frame(tj[0], tj[1], tj[2], uj, u, w);
        weight += c.area[*j];
      }
      smoothed.row(v) = weight > 0 ? Eigen::RowVector3d(sum.transpose() / weight) : Eigen::RowVector3d(tensor.row(v));
    });
    tensor = std::move(smoothed);
  }
  parallel_range(nv, diagonalize_vertex);
  return c;
}

}  // namespace vertexflow
