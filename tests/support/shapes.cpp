#include "shapes.h"

#include <cmath>
#include <map>
#include <vector>

namespace vertexflow::test {
namespace {

Mesh from_lists(const std::vector<Eigen::Vector3d>& points, const std::vector<Eigen::Vector3i>& triangles) {
  Mesh mesh;
  mesh.V.resize(static_cast<Eigen::Index>(points.size()), 3);
  for (std::size_t i = 0; i < points.size(); ++i) mesh.V.row(static_cast<Eigen::Index>(i)) = points[i].transpose();
  mesh.F.resize(static_cast<Eigen::Index>(triangles.size()), 3);
  for (std::size_t i = 0; i < triangles.size(); ++i) mesh.F.row(static_cast<Eigen::Index>(i)) = triangles[i].transpose();
  return mesh;
}

// Triangulates a grid of (rows + 1) x (cols + 1) points indexed by index(i, j), alternating the
// diagonal so the mesh has no directional bias.
void grid_triangles(int rows, int cols, const auto& index, std::vector<Eigen::Vector3i>& out) {
  for (int i = 0; i < rows; ++i) {
    for (int j = 0; j < cols; ++j) {
      const int a = index(i, j), b = index(i + 1, j), c = index(i + 1, j + 1), d = index(i, j + 1);
      if ((i + j) % 2 == 0) {
        out.emplace_back(a, b, c);
        out.emplace_back(a, c, d);
      } else {
        out.emplace_back(a, b, d);
        out.emplace_back(b, c, d);
      }
    }
  }
}

}  // namespace

Mesh icosphere(double radius, int levels) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Eigen::Vector3d> p = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                                    {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  std::vector<Eigen::Vector3i> f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                                    {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                                    {3, 8, 9},  {4, 9, 5},   {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (auto& q : p) q.normalize();
  for (int level = 0; level < levels; ++level) {
    std::map<std::pair<int, int>, int> midpoint;
    auto mid = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      const auto it = midpoint.find(key);
      if (it != midpoint.end()) return it->second;
      p.push_back((p[static_cast<std::size_t>(a)] + p[static_cast<std::size_t>(b)]).normalized());
      return midpoint[key] = static_cast<int>(p.size()) - 1;
    };
    std::vector<Eigen::Vector3i> next;
    for (const auto& tri : f) {
      const int ab = mid(tri[0], tri[1]), bc = mid(tri[1], tri[2]), ca = mid(tri[2], tri[0]);
      next.emplace_back(tri[0], ab, ca);
      next.emplace_back(tri[1], bc, ab);
      next.emplace_back(tri[2], ca, bc);
      next.emplace_back(ab, bc, ca);
    }
    f = std::move(next);
  }
  for (auto& q : p) q *= radius;
  return from_lists(p, f);
}

Mesh cylinder(double radius, double height, int around, int along) {
  std::vector<Eigen::Vector3d> p;
  for (int i = 0; i <= along; ++i) {
    for (int j = 0; j < around; ++j) {
      const double phi = 2 * M_PI * j / around;
      p.emplace_back(radius * std::cos(phi), radius * std::sin(phi), height * i / along);
    }
  }
  std::vector<Eigen::Vector3i> f;
  // Rows go up in z and columns counter-clockwise about z: (i, j) -> (i, j+1) -> (i+1, j+1)
  // faces outwards.
  grid_triangles(along, around, [&](int i, int j) { return i * around + j % around; }, f);
  for (auto& tri : f) std::swap(tri[1], tri[2]);
  return from_lists(p, f);
}

Mesh torus(double R, double r, int around, int tube) {
  std::vector<Eigen::Vector3d> p;
  for (int i = 0; i < around; ++i) {
    const double phi = 2 * M_PI * i / around;
    for (int j = 0; j < tube; ++j) {
      const double theta = 2 * M_PI * j / tube;
      const double rho = R + r * std::cos(theta);
      p.emplace_back(rho * std::cos(phi), rho * std::sin(phi), r * std::sin(theta));
    }
  }
  std::vector<Eigen::Vector3i> f;
  grid_triangles(around, tube, [&](int i, int j) { return (i % around) * tube + j % tube; }, f);
  return from_lists(p, f);
}

Mesh saddle(double half, int n) {
  std::vector<Eigen::Vector3d> p;
  for (int i = 0; i <= n; ++i) {
    for (int j = 0; j <= n; ++j) {
      const double x = -half + 2 * half * i / n, y = -half + 2 * half * j / n;
      p.emplace_back(x, y, 0.5 * (x * x - y * y));
    }
  }
  std::vector<Eigen::Vector3i> f;
  grid_triangles(n, n, [&](int i, int j) { return i * (n + 1) + j; }, f);
  return from_lists(p, f);
}

}  // namespace vertexflow::test
