// Rusinkiewicz (2004) curvature estimation; see include/vertexflow/curvature.h for the
// conventions. Every pass is either "per face, write own slots" or "per vertex, gather from
// incident faces in the topology's fixed order", so results do not depend on thread count.
#include "vertexflow/curvature.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Eigen/Dense>

#include <cmath>

namespace vertexflow {
namespace {

using CornerAreas = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;

template <class Body>
void parallel_range(Index n, Body&& body) {
  tbb::parallel_for(tbb::blocked_range<Index>(0, n, 2048), [&](const tbb::blocked_range<Index>& r) {
    for (Index i = r.begin(); i != r.end(); ++i) body(i);
  });
}

Eigen::Vector3d position(const Vertices& V, Index v) { return V.row(v).transpose(); }

// Contribution of corner k of face f to its vertex's normal.
Eigen::Vector3d corner_normal(const Vertices& V, const Faces& F, Index f, int k, NormalWeighting weighting) {
  const Eigen::Vector3d p = position(V, F(f, k));
  const Eigen::Vector3d a = position(V, F(f, (k + 1) % 3)) - p;
  const Eigen::Vector3d b = position(V, F(f, (k + 2) % 3)) - p;
  const Eigen::Vector3d n = a.cross(b);
  switch (weighting) {
    case NormalWeighting::Max1999: {
      const double scale = a.squaredNorm() * b.squaredNorm();
      return scale > 0 ? Eigen::Vector3d(n / scale) : Eigen::Vector3d::Zero();
    }
    case NormalWeighting::Area:
      return n;
    case NormalWeighting::Angle: {
      const double length = n.norm();
      if (!(length > 0)) return Eigen::Vector3d::Zero();
      return std::atan2(length, a.dot(b)) * n / length;
    }
  }
  return n;
}

// Meyer et al. (2003) mixed areas of the three corners of one face.
Eigen::Vector3d face_corner_areas(const Vertices& V, const Faces& F, Index f) {
  const Eigen::Vector3d p[3] = {position(V, F(f, 0)), position(V, F(f, 1)), position(V, F(f, 2))};
  const double area = 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).norm();
  Eigen::Vector3d result = Eigen::Vector3d::Zero();
  if (!(area > 0)) return result;
  double dot[3];  // dot products of the two edges at each corner (negative = obtuse)
  for (int k = 0; k < 3; ++k) dot[k] = (p[(k + 1) % 3] - p[k]).dot(p[(k + 2) % 3] - p[k]);
  for (int k = 0; k < 3; ++k) {
    if (dot[k] < 0) {  // obtuse at k: half to k, a quarter to each other corner
      result.setConstant(0.25 * area);
      result[k] = 0.5 * area;
      return result;
    }
  }
  // Voronoi region of corner k: (|p_k p_j|^2 cot(angle at l) + |p_k p_l|^2 cot(angle at j)) / 8,
  // with cot(angle at m) = dot[m] / (2 area).
  for (int k = 0; k < 3; ++k) {
    const int j = (k + 1) % 3, l = (k + 2) % 3;
    result[k] = ((p[j] - p[k]).squaredNorm() * dot[l] + (p[l] - p[k]).squaredNorm() * dot[j]) / (16.0 * area);
  }
  return result;
}

// The second fundamental form of one face, [[e, f], [f, g]] in the face's frame (t, b), with
// face normal n = t x b.
struct FaceTensor {
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  double e = 0, f = 0, g = 0;
  bool valid = false;
};

// Least-squares fit (Rusinkiewicz 2004, section 3): for each edge E (from corner j to corner
// l), II * (E.t, E.b) = ((N_l - N_j).t, (N_l - N_j).b). Six equations, three unknowns.
FaceTensor fit_face_tensor(const Vertices& V, const Faces& F, const Vertices& N, Index face) {
  FaceTensor ft;
  const Eigen::Vector3d p[3] = {position(V, F(face, 0)), position(V, F(face, 1)), position(V, F(face, 2))};
  const Eigen::Vector3d normal = (p[1] - p[0]).cross(p[2] - p[0]);
  const double edge = (p[2] - p[1]).norm();
  if (!(normal.norm() > 0) || !(edge > 0)) return ft;
  ft.t = (p[2] - p[1]) / edge;
  ft.b = normal.normalized().cross(ft.t);
  Eigen::Matrix<double, 6, 3> A = Eigen::Matrix<double, 6, 3>::Zero();
  Eigen::Matrix<double, 6, 1> rhs;
  for (int k = 0; k < 3; ++k) {
    const int j = (k + 1) % 3, l = (k + 2) % 3;
    const Eigen::Vector3d E = p[l] - p[j];
    const Eigen::Vector3d dN = N.row(F(face, l)).transpose() - N.row(F(face, j)).transpose();
    const double u = E.dot(ft.t), v = E.dot(ft.b);
    A.row(2 * k) << u, v, 0;
    A.row(2 * k + 1) << 0, u, v;
    rhs[2 * k] = dN.dot(ft.t);
    rhs[2 * k + 1] = dN.dot(ft.b);
  }
  // A robust small solve: the normal matrix is positive definite for any non-degenerate
  // triangle, and Eigen's pivoted LDLT handles the ill-conditioned ones (needles) without
  // reading unwritten entries, the flaw of the widely copied hand-written 3x3 LDLT.
  const Eigen::Matrix3d normal_matrix = A.transpose() * A;
  const Eigen::Vector3d solution = normal_matrix.ldlt().solve(A.transpose() * rhs);
  if (!solution.allFinite()) return ft;
  ft.e = solution[0];
  ft.f = solution[1];
  ft.g = solution[2];
  ft.valid = true;
  return ft;
}

// Rotates x by the smallest rotation taking unit vector `from` to unit vector `to`
// (Rodrigues: R x = x + w x x + w x (w x x) / (1 + from.to), w = from x to).
Eigen::Vector3d rotate_between(const Eigen::Vector3d& x, const Eigen::Vector3d& from, const Eigen::Vector3d& to) {
  const Eigen::Vector3d w = from.cross(to);
  const double c = from.dot(to);
  const Eigen::Vector3d wx = w.cross(x);
  return x + wx + w.cross(wx) / (1.0 + c);
}

// The symmetric tensor (ku, kuv, kv) in the vertex frame (u, v) of a tensor given in another
// frame (t, b) whose normal has been rotated onto the vertex normal.
Eigen::Vector3d tensor_in_frame(double e, double f, double g, const Eigen::Vector3d& t, const Eigen::Vector3d& b,
                                const Eigen::Vector3d& u, const Eigen::Vector3d& v) {
  const double u1 = u.dot(t), v1 = u.dot(b);
  const double u2 = v.dot(t), v2 = v.dot(b);
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
  const double radius = std::hypot(0.5 * (ku - kv), kuv);
  k1 = mean + radius;
  k2 = mean - radius;
  const double angle = 0.5 * std::atan2(2 * kuv, ku - kv);  // direction of the larger eigenvalue
  t1 = std::cos(angle) * u + std::sin(angle) * v;
  t2 = n.cross(t1);
}

}  // namespace

Vertices vertex_normals(const Vertices& V, const Faces& F, NormalWeighting weighting) {
  Vertices N = Vertices::Zero(V.rows(), 3);
  for (Index f = 0; f < F.rows(); ++f) {
    for (int k = 0; k < 3; ++k) N.row(F(f, k)) += corner_normal(V, F, f, k, weighting).transpose();
  }
  for (Index v = 0; v < V.rows(); ++v) {
    const double length = N.row(v).norm();
    N.row(v) = length > 0 ? Eigen::RowVector3d(N.row(v) / length) : Eigen::RowVector3d(0, 0, 1);
  }
  return N;
}

CornerAreas corner_areas(const Vertices& V, const Faces& F) {
  CornerAreas areas(F.rows(), 3);
  parallel_range(static_cast<Index>(F.rows()), [&](Index f) { areas.row(f) = face_corner_areas(V, F, f).transpose(); });
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
  Curvature c;
  c.k1 = Eigen::VectorXd::Zero(nv);
  c.k2 = Eigen::VectorXd::Zero(nv);
  c.T1.resize(nv, 3);
  c.T2.resize(nv, 3);
  c.N.resize(nv, 3);
  c.area = Eigen::VectorXd::Zero(nv);

  auto corner_of = [&](Index f, Index v) { return F(f, 0) == v ? 0 : F(f, 1) == v ? 1 : 2; };
  auto for_incident_faces = [&](Index v, auto&& body) {
    for (Index i = topology.face_offsets[static_cast<std::size_t>(v)]; i < topology.face_offsets[static_cast<std::size_t>(v) + 1]; ++i) {
      const Index f = topology.vertex_faces[static_cast<std::size_t>(i)];
      body(f, corner_of(f, v));
    }
  };

  // Pass 1, per face: corner areas.
  const CornerAreas corner_area = corner_areas(V, F);

  // Pass 2, per vertex: normal, area, and a tangent frame (u, v, N).
  Vertices U(nv, 3);
  parallel_range(nv, [&](Index v) {
    Eigen::Vector3d normal = Eigen::Vector3d::Zero();
    double area = 0;
    for_incident_faces(v, [&](Index f, int k) {
      normal += corner_normal(V, F, f, k, options.normal_weighting);
      area += corner_area(f, k);
    });
    const double length = normal.norm();
    normal = length > 0 ? Eigen::Vector3d(normal / length) : Eigen::Vector3d(0, 0, 1);
    c.N.row(v) = normal.transpose();
    c.area[v] = area;
    U.row(v) = normal.unitOrthogonal().transpose();
  });

  // Pass 3, per face: the fitted second fundamental form.
  std::vector<FaceTensor> face_tensor(static_cast<std::size_t>(nf));
  parallel_range(nf, [&](Index f) { face_tensor[static_cast<std::size_t>(f)] = fit_face_tensor(V, F, c.N, f); });

  // Pass 4, per vertex: area-weighted average of the incident face tensors, each rotated into
  // the vertex's tangent plane (Rusinkiewicz 2004, section 4).
  Vertices tensor = Vertices::Zero(nv, 3);
  parallel_range(nv, [&](Index v) {
    const Eigen::Vector3d n = c.N.row(v).transpose(), u = U.row(v).transpose(), w = n.cross(u);
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    double weight = 0;
    for_incident_faces(v, [&](Index f, int k) {
      const FaceTensor& ft = face_tensor[static_cast<std::size_t>(f)];
      if (!ft.valid || !(corner_area(f, k) > 0)) return;
      const Eigen::Vector3d face_normal = ft.t.cross(ft.b);
      if (face_normal.dot(n) <= kFoldedCosine) return;
      const Eigen::Vector3d t = rotate_between(ft.t, face_normal, n);
      const Eigen::Vector3d b = rotate_between(ft.b, face_normal, n);
      sum += corner_area(f, k) * tensor_in_frame(ft.e, ft.f, ft.g, t, b, u, w);
      weight += corner_area(f, k);
    });
    if (weight > 0) tensor.row(v) = (sum / weight).transpose();
  });

  // Optional smoothing: average each tensor with its neighbours', transported likewise.
  for (int round = 0; round < options.smoothing_rounds; ++round) {
    Vertices smoothed(nv, 3);
    parallel_range(nv, [&](Index v) {
      const Eigen::Vector3d n = c.N.row(v).transpose(), u = U.row(v).transpose(), w = n.cross(u);
      Eigen::Vector3d sum = c.area[v] * tensor.row(v).transpose();
      double weight = c.area[v];
      const auto [begin, end] = topology.ring(v);
      for (const Index* j = begin; j != end; ++j) {
        const Eigen::Vector3d nj = c.N.row(*j).transpose();
        if (nj.dot(n) <= kFoldedCosine) continue;
        const Eigen::Vector3d uj = rotate_between(U.row(*j).transpose(), nj, n);
        const Eigen::Vector3d wj = rotate_between(nj.cross(U.row(*j).transpose()), nj, n);
        const Eigen::Vector3d tj = tensor.row(*j).transpose();
        sum += c.area[*j] * tensor_in_frame(tj[0], tj[1], tj[2], uj, wj, u, w);
        weight += c.area[*j];
      }
      smoothed.row(v) = weight > 0 ? Eigen::RowVector3d(sum.transpose() / weight) : Eigen::RowVector3d(tensor.row(v));
    });
    tensor = std::move(smoothed);
  }

  // Pass 5, per vertex: principal curvatures and directions.
  parallel_range(nv, [&](Index v) {
    const Eigen::Vector3d n = c.N.row(v).transpose(), u = U.row(v).transpose(), w = n.cross(u);
    double k1 = 0, k2 = 0;
    Eigen::Vector3d t1, t2;
    diagonalize(tensor.row(v).transpose(), u, w, n, k1, k2, t1, t2);
    c.k1[v] = k1;
    c.k2[v] = k2;
    c.T1.row(v) = t1.transpose();
    c.T2.row(v) = t2.transpose();
  });
  return c;
}

}  // namespace vertexflow
