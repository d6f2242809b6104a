// Internal: the closest point of a triangle to a point, with its barycentric coordinates, shared
// by the flow's projection (flow/surface_projection.cpp) and attribute transport
// (attributes/transport.cpp).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace vertexflow {

struct TrianglePoint {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  /// Weights of the corners a, b, d: point = w0 a + w1 b + w2 d, each in [0, 1], sum 1.
  Eigen::Vector3d barycentric = Eigen::Vector3d::Zero();
  /// False for a degenerate triangle (zero area), which has no well-defined closest point.
  bool valid = false;
};

/// Closest point of triangle (a, b, d) to x. Written out (the region test of Ericson, Real-Time
/// Collision Detection, 5.1.5: which vertex, edge or interior region of the triangle x projects
/// into, from six dot products) rather than CGAL's Construct_projected_point_3 on a Triangle_3:
/// CGAL's builds the triangle, tests it for collinearity and projects through several
/// constructions, and was 42% of the time of the density passes (FlowOptions::density), which
/// project every vertex 30 times.
inline TrianglePoint closest_point_on_triangle(const Eigen::Vector3d& x, const Eigen::Vector3d& a,
                                               const Eigen::Vector3d& b, const Eigen::Vector3d& d) {
  TrianglePoint c;
  const Eigen::Vector3d ab = b - a, ad = d - a;
  if (!(ab.cross(ad).squaredNorm() > 0)) return c;
  c.valid = true;
  const Eigen::Vector3d ax = x - a;
  const double d1 = ab.dot(ax), d2 = ad.dot(ax);
  if (d1 <= 0 && d2 <= 0) {
    c.point = a;  // vertex region a
    c.barycentric = {1, 0, 0};
    return c;
  }
  const Eigen::Vector3d bx = x - b;
  const double d3 = ab.dot(bx), d4 = ad.dot(bx);
  const Eigen::Vector3d dx = x - d;
  const double d5 = ab.dot(dx), d6 = ad.dot(dx);
  const double vc = d1 * d4 - d3 * d2, vb = d5 * d2 - d1 * d6, va = d3 * d6 - d5 * d4;
  if (d3 >= 0 && d4 <= d3) {
    c.point = b;  // vertex region b
    c.barycentric = {0, 1, 0};
  } else if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const double t = d1 / (d1 - d3);  // edge ab
    c.point = a + t * ab;
    c.barycentric = {1 - t, t, 0};
  } else if (d6 >= 0 && d5 <= d6) {
    c.point = d;  // vertex region d
    c.barycentric = {0, 0, 1};
  } else if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const double t = d2 / (d2 - d6);  // edge ad
    c.point = a + t * ad;
    c.barycentric = {1 - t, 0, t};
  } else if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    const double t = (d4 - d3) / ((d4 - d3) + (d5 - d6));  // edge bd
    c.point = b + t * (d - b);
    c.barycentric = {0, 1 - t, t};
  } else {
    const double denominator = 1.0 / (va + vb + vc);  // interior: barycentric (va, vb, vc)
    const double v = vb * denominator, w = vc * denominator;
    c.point = a + v * ab + w * ad;
    c.barycentric = {1 - v - w, v, w};
  }
  return c;
}

}  // namespace vertexflow
