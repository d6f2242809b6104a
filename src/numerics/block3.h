// Internal: vectors of 3-blocks (x, y, z of one vertex or node, the layout of Vertices'
// storage: x0 y0 z0 x1 ...) and symmetric 3x3 blocks, the unknowns and the per-vertex factors
// of the flow's normal equations and of the multilevel preconditioner.
#pragma once

#include "numerics/parallel.h"
#include "vertexflow/mesh.h"

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <vector>

namespace vertexflow {

/// 3 entries per vertex (or node), x0 y0 z0 x1 ...
using BlockVector = Eigen::VectorXd;

/// Block i of a BlockVector.
inline Eigen::Map<Eigen::Vector3d> block_at(BlockVector& v, Index i) {
  return Eigen::Map<Eigen::Vector3d>(v.data() + 3 * static_cast<Eigen::Index>(i));
}
inline Eigen::Map<const Eigen::Vector3d> block_at(const BlockVector& v, Index i) {
  return Eigen::Map<const Eigen::Vector3d>(v.data() + 3 * static_cast<Eigen::Index>(i));
}

/// A symmetric 3x3 matrix stored as its upper triangle: the iterations that use these are
/// bound by memory traffic, so 48 bytes instead of 72 matter. Products and full() are in
/// double whatever the storage: `Sym3f` (24 bytes) rounds the entries once when it is made,
/// so the operator it builds is still exactly symmetric, only of slightly rounded factors.
template <class Scalar>
struct BasicSym3 {
  Scalar xx = 0, xy = 0, xz = 0, yy = 0, yz = 0, zz = 0;

  BasicSym3() = default;
  explicit BasicSym3(const Eigen::Matrix3d& m)
      : xx(static_cast<Scalar>(m(0, 0))),
        xy(static_cast<Scalar>(m(0, 1))),
        xz(static_cast<Scalar>(m(0, 2))),
        yy(static_cast<Scalar>(m(1, 1))),
        yz(static_cast<Scalar>(m(1, 2))),
        zz(static_cast<Scalar>(m(2, 2))) {}
  [[nodiscard]] Eigen::Matrix3d full() const {
    Eigen::Matrix3d m;
    m << xx, xy, xz, xy, yy, yz, xz, yz, zz;
    return m;
  }
  [[nodiscard]] double trace() const { return double(xx) + double(yy) + double(zz); }
  [[nodiscard]] Eigen::Vector3d operator*(const Eigen::Vector3d& v) const {
    const double a = xx, b = xy, c = xz, d = yy, e = yz, f = zz;
    return {a * v.x() + b * v.y() + c * v.z(), b * v.x() + d * v.y() + e * v.z(), c * v.x() + e * v.y() + f * v.z()};
  }
};
using Sym3 = BasicSym3<double>;
using Sym3f = BasicSym3<float>;

/// A symmetric positive definite 3x3 inverse B = M^T M kept as M, lower triangular, in float (24
/// bytes): block-Jacobi's per-vertex inverses, read at every iteration. Rounding M rather than B
/// keeps B positive definite however anisotropic the block (stiff along a normal, soft in the
/// tangent plane), where a rounded B could lose definiteness; B is exactly symmetric and the
/// same on any processor. Products are in double.
struct InverseFactor3f {
  float m00 = 0, m10 = 0, m11 = 0, m20 = 0, m21 = 0, m22 = 0;

  /// B = block^-1, block symmetric positive definite: M = L^-1 with block = L L^T (Cholesky).
  /// A block that is not numerically positive definite (rounding on a degenerate input) gets B
  /// = (3 / trace) I if its trace is positive, else 0.
  static InverseFactor3f of_inverse(const Eigen::Matrix3d& block) {
    const Eigen::LLT<Eigen::Matrix3d> llt(block);
    if (llt.info() != Eigen::Success || !(llt.matrixLLT().diagonal().minCoeff() > 0)) {
      const double trace = block.trace();
      return scalar(trace > 0 ? 3.0 / trace : 0.0);
    }
    const Eigen::Matrix3d M = llt.matrixL().solve(Eigen::Matrix3d::Identity());  // lower triangular, as L^-1 is
    InverseFactor3f f;
    f.m00 = static_cast<float>(M(0, 0)), f.m10 = static_cast<float>(M(1, 0)), f.m11 = static_cast<float>(M(1, 1));
    f.m20 = static_cast<float>(M(2, 0)), f.m21 = static_cast<float>(M(2, 1)), f.m22 = static_cast<float>(M(2, 2));
    return f;
  }
  /// B = scale I, scale >= 0.
  static InverseFactor3f scalar(double scale) {
    InverseFactor3f f;
    f.m00 = f.m11 = f.m22 = static_cast<float>(std::sqrt(scale));
    return f;
  }

  /// B r = M^T (M r).
  [[nodiscard]] Eigen::Vector3d operator*(const Eigen::Vector3d& r) const {
    const double a = m00, b = m10, c = m11, d = m20, e = m21, f = m22;
    const double u = a * r.x(), v = b * r.x() + c * r.y(), w = d * r.x() + e * r.y() + f * r.z();
    return {a * u + b * v + d * w, c * v + e * w, f * w};
  }
};

/// Sym3f blocks of consecutive indices stored four at a time, each entry's four values side by
/// side (xx of blocks 4g..4g+3, then their xy, ...): the same 24 bytes per block, but a pass
/// that works on four vertices at once (flow_operator.cpp) loads an entry of all four with one
/// instruction instead of gathering it from four records. Indexing gives a Sym3f by value.
class Sym3fGroups {
 public:
  static constexpr int kWidth = 4;
  struct Group {
    float xx[kWidth], xy[kWidth], xz[kWidth], yy[kWidth], yz[kWidth], zz[kWidth];
  };

  /// n blocks, all zero (the last group's unused lanes stay zero).
  void assign_zero(std::size_t n) { groups_.assign((n + kWidth - 1) / kWidth, Group{}); }
  [[nodiscard]] Sym3f operator[](std::size_t i) const {
    const Group& g = groups_[i / kWidth];
    const std::size_t l = i % kWidth;
    Sym3f s;
    s.xx = g.xx[l], s.xy = g.xy[l], s.xz = g.xz[l], s.yy = g.yy[l], s.yz = g.yz[l], s.zz = g.zz[l];
    return s;
  }
  void set(std::size_t i, const Sym3f& s) {
    Group& g = groups_[i / kWidth];
    const std::size_t l = i % kWidth;
    g.xx[l] = s.xx, g.xy[l] = s.xy, g.xz[l] = s.xz, g.yy[l] = s.yy, g.yz[l] = s.yz, g.zz[l] = s.zz;
  }
  /// Group g: blocks kWidth g .. kWidth g + kWidth - 1.
  [[nodiscard]] const Group& group(std::size_t g) const { return groups_[g]; }

 private:
  std::vector<Group> groups_;
};

/// a . b, summed in chunks of 8192 entries in order (deterministic_sum), so that its rounding
/// does not depend on the threads.
inline double deterministic_dot(const BlockVector& a, const BlockVector& b) {
  return deterministic_sum(a.size(), 8192, 0.0, [&](std::ptrdiff_t begin, std::ptrdiff_t end) {
    return a.segment(begin, end - begin).dot(b.segment(begin, end - begin));
  });
}

}  // namespace vertexflow
