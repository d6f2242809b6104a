// The derivative of curvature (curvature.h, curvature_derivative): Rusinkiewicz 2004, section 5.
// Scalar code on Eigen vectors: it runs once per line drawing, not inside the flow's loop, so
// it does not share the vectorised passes of curvature.cpp.
#include "numerics/parallel.h"
#include "vertexflow/curvature.h"

#include <Eigen/Cholesky>

#include <array>
#include <stdexcept>
#include <vector>

namespace vertexflow {
namespace {

// A symmetric 2 x 2 x 2 tensor by its four independent components C111, C112, C122, C222.
using Tensor3 = Eigen::Vector4d;

// Component C(i, j, k) for indices in {0, 1}: the number of 1s picks the component.
double component(const Tensor3& c, int i, int j, int k) {
  return c[i + j + k];
}

// The tensor in a basis e'_p = sum_i M(i, p) e_i, M orthonormal: C'(p, q, r) = sum C(i, j, k)
// M(i, p) M(j, q) M(k, r).
Tensor3 change_basis(const Tensor3& c, const Eigen::Matrix2d& M) {
  Tensor3 out;
  const int indices[4][3] = {{0, 0, 0}, {0, 0, 1}, {0, 1, 1}, {1, 1, 1}};
  for (int n = 0; n < 4; ++n) {
    const auto [p, q, r] = indices[n];
    double sum = 0;
    for (int i = 0; i < 2; ++i)
      for (int j = 0; j < 2; ++j)
        for (int k = 0; k < 2; ++k) sum += component(c, i, j, k) * M(i, p) * M(j, q) * M(k, r);
    out[n] = sum;
  }
  return out;
}

// The vector t of the tangent plane of unit normal `from`, carried into the tangent plane of
// unit normal `to` by the smallest rotation taking `from` to `to` (t orthogonal to `from`).
Eigen::Vector3d carry(const Eigen::Vector3d& t, const Eigen::Vector3d& from, const Eigen::Vector3d& to) {
  return t - (to.dot(t) / (1.0 + from.dot(to))) * (from + to);
}

// Faces whose normal is this close to the opposite of a vertex normal cannot be rotated into its
// plane (as in curvature.cpp).
constexpr double kFolded = -0.99;

}  // namespace

double CurvatureDerivative::evaluate(Index i, const Eigen::Vector2d& x, const Eigen::Vector2d& y,
                                     const Eigen::Vector2d& z) const {
  const Tensor3 c = C.row(i).transpose();
  double sum = 0;
  for (int a = 0; a < 2; ++a)
    for (int b = 0; b < 2; ++b)
      for (int d = 0; d < 2; ++d) sum += component(c, a, b, d) * x[a] * y[b] * z[d];
  return sum;
}

CurvatureDerivative curvature_derivative(const Vertices& V, const Faces& F, const Topology& topology,
                                         const Curvature& curvature) {
  const Index n = V.rows(), m = F.rows();
  if (curvature.k1.size() != n || topology.num_vertices != n || topology.num_faces != m)
    throw std::invalid_argument("curvature derivative: the curvature or topology is for another mesh");
  const auto areas = corner_areas(V, F);
  // Per face: C in the face's frame (t along edge 0, b = normal x t), and whether it is usable.
  std::vector<Tensor3> face_tensor(static_cast<std::size_t>(m), Tensor3::Zero());
  std::vector<Eigen::Matrix3d> face_frame(static_cast<std::size_t>(m));  // columns t, b, normal
  std::vector<char> usable(static_cast<std::size_t>(m), 0);
  parallel_for_index(m, [&](Index f) {
    const Eigen::Vector3d p[3] = {V.row(F(f, 0)).transpose(), V.row(F(f, 1)).transpose(), V.row(F(f, 2)).transpose()};
    Eigen::Vector3d normal = (p[1] - p[0]).cross(p[2] - p[0]);
    if (!(normal.norm() > 0)) return;
    normal.normalize();
    const Eigen::Vector3d t = (p[1] - p[0]).normalized(), b = normal.cross(t);
    // Each corner's II in the face frame: its principal frame carried into the face's plane.
    std::array<Eigen::Matrix2d, 3> second;
    for (int k = 0; k < 3; ++k) {
      const Index v = F(f, k);
      const Eigen::Vector3d N = curvature.N.row(v).transpose();
      if (N.dot(normal) < kFolded) return;
      const Eigen::Vector3d T1 = carry(curvature.T1.row(v).transpose(), N, normal);
      const Eigen::Vector3d T2 = carry(curvature.T2.row(v).transpose(), N, normal);
      Eigen::Matrix2d frame;  // rows: T1, T2 in (t, b)
      frame << T1.dot(t), T1.dot(b), T2.dot(t), T2.dot(b);
      second[k] = frame.transpose() * Eigen::Vector2d(curvature.k1[v], curvature.k2[v]).asDiagonal() * frame;
    }
    // Least squares over the three edges: along the edge with coordinates (u, w) from corner j to
    // corner l, II_l - II_j = u D_t II + w D_b II, that is (Delta e, Delta f, Delta g) =
    // (u a + w b, u b + w c, u c + w d) for C = (a, b, c, d); f counts twice (the Frobenius norm).
    Eigen::Matrix4d A = Eigen::Matrix4d::Zero();
    Eigen::Vector4d r = Eigen::Vector4d::Zero();
    for (int k = 0; k < 3; ++k) {
      const int j = (k + 1) % 3, l = (k + 2) % 3;
      const Eigen::Vector3d edge = p[l] - p[j];
      const double u = edge.dot(t), w = edge.dot(b);
      const Eigen::Matrix2d delta = second[l] - second[j];
      const Eigen::Vector4d rows[3] = {{u, w, 0, 0}, {0, u, w, 0}, {0, 0, u, w}};
      const double rhs[3] = {delta(0, 0), delta(0, 1), delta(1, 1)};
      const double weight[3] = {1, 2, 1};
      for (int e = 0; e < 3; ++e) {
        A += weight[e] * rows[e] * rows[e].transpose();
        r += weight[e] * rhs[e] * rows[e];
      }
    }
    const Eigen::LDLT<Eigen::Matrix4d> solve(A);
    if (solve.info() != Eigen::Success) return;
    const Tensor3 c = solve.solve(r);
    if (!c.allFinite()) return;
    face_tensor[static_cast<std::size_t>(f)] = c;
    face_frame[static_cast<std::size_t>(f)].col(0) = t;
    face_frame[static_cast<std::size_t>(f)].col(1) = b;
    face_frame[static_cast<std::size_t>(f)].col(2) = normal;
    usable[static_cast<std::size_t>(f)] = 1;
  });

  // Per vertex: its faces' tensors in its principal frame, weighted by their corner areas, in the
  // topology's fixed order (the same sums for any thread count).
  CurvatureDerivative result;
  result.C.setZero(n, 4);
  parallel_for_index(n, [&](Index v) {
    const Eigen::Vector3d N = curvature.N.row(v).transpose(), T1 = curvature.T1.row(v).transpose(),
                          T2 = curvature.T2.row(v).transpose();
    Tensor3 sum = Tensor3::Zero();
    double weights = 0;
    for (Index s = topology.face_offsets[static_cast<std::size_t>(v)];
         s < topology.face_offsets[static_cast<std::size_t>(v) + 1]; ++s) {
      const Index f = topology.vertex_faces[static_cast<std::size_t>(s)];
      if (!usable[static_cast<std::size_t>(f)]) continue;
      const Eigen::Matrix3d& frame = face_frame[static_cast<std::size_t>(f)];
      if (frame.col(2).dot(N) < kFolded) continue;
      // The face's (t, b) carried into the vertex's plane, in the vertex's (T1, T2).
      const Eigen::Vector3d t = carry(frame.col(0), frame.col(2), N), b = carry(frame.col(1), frame.col(2), N);
      Eigen::Matrix2d M;  // M(i, p): face basis vector i in vertex basis p
      M << t.dot(T1), t.dot(T2), b.dot(T1), b.dot(T2);
      int corner = 0;
      while (F(f, corner) != v) ++corner;
      const double weight = areas(f, corner);
      sum += weight * change_basis(face_tensor[static_cast<std::size_t>(f)], M);
      weights += weight;
    }
    if (weights > 0) result.C.row(v) = (sum / weights).transpose();
  });
  return result;
}

}  // namespace vertexflow
