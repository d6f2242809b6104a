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
/// bound by memory traffic, so 48 bytes instead of 72 matter.
struct Sym3 {
  double xx = 0, xy = 0, xz = 0, yy = 0, yz = 0, zz = 0;

  Sym3() = default;
  explicit Sym3(const Eigen::Matrix3d& m)
      : xx(m(0, 0)), xy(m(0, 1)), xz(m(0, 2)), yy(m(1, 1)), yz(m(1, 2)), zz(m(2, 2)) {}
  [[nodiscard]] Eigen::Matrix3d full() const {
    Eigen::Matrix3d m;
    m << xx, xy, xz, xy, yy, yz, xz, yz, zz;
    return m;
  }
  [[nodiscard]] double trace() const { return xx + yy + zz; }
  [[nodiscard]] Eigen::Vector3d operator*(const Eigen::Vector3d& v) const {
    return {xx * v.x() + xy * v.y() + xz * v.z(), xy * v.x() + yy * v.y() + yz * v.z(),
            xz * v.x() + yz * v.y() + zz * v.z()};
  }
};

/// a . b, summed in chunks of 8192 entries in order (deterministic_sum), so that its rounding
/// does not depend on the threads.
inline double deterministic_dot(const BlockVector& a, const BlockVector& b) {
  return deterministic_sum(a.size(), 8192, 0.0, [&](std::ptrdiff_t begin, std::ptrdiff_t end) {
    return a.segment(begin, end - begin).dot(b.segment(begin, end - begin));
  });
}

}  // namespace vertexflow
