// Internal: vectors of 3-blocks (x, y, z of one vertex or node, the layout of Vertices'
// storage: x0 y0 z0 x1 ...) and symmetric 3x3 blocks, the unknowns and the per-vertex factors
// of the flow's normal equations and of the multilevel preconditioner.
#pragma once

#include "numerics/parallel.h"
#include "vertexflow/mesh.h"

#include <Eigen/Core>

#include <algorithm>
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
