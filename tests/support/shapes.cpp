#include "shapes.h"

#include "vertexflow/curvature.h"
#include "vertexflow/topology.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numeric>
#include <random>
#include <set>
#include <vector>

namespace vertexflow::test {
namespace {

Mesh from_lists(const std::vector<Eigen::Vector3d>& points, const std::vector<Eigen::Vector3i>& triangles) {
  Mesh mesh;
  mesh.V.resize(static_cast<Eigen::Index>(points.size()), 3);
  for (std::size_t i = 0; i < points.size(); ++i) mesh.V.row(static_cast<Eigen::Index>(i)) = points[i].transpose();
  mesh.F.resize(static_cast<Eigen::Index>(triangles.size()), 3);
  for (std::size_t i = 0; i < triangles.size(); ++i)
    mesh.F.row(static_cast<Eigen::Index>(i)) = triangles[i].transpose();
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

Renumbered renumbered(const Mesh& mesh, unsigned seed, bool rotate_corners) {
  std::mt19937 random(seed);
  Renumbered out;
  out.new_index.resize(static_cast<std::size_t>(mesh.num_vertices()));
  std::iota(out.new_index.begin(), out.new_index.end(), Index{0});
  std::shuffle(out.new_index.begin(), out.new_index.end(), random);
  std::vector<Index> face_order(static_cast<std::size_t>(mesh.num_faces()));
  std::iota(face_order.begin(), face_order.end(), Index{0});
  std::shuffle(face_order.begin(), face_order.end(), random);
  out.mesh.V.resize(mesh.num_vertices(), 3);
  for (Index v = 0; v < mesh.num_vertices(); ++v)
    out.mesh.V.row(out.new_index[static_cast<std::size_t>(v)]) = mesh.V.row(v);
  out.mesh.F.resize(mesh.num_faces(), 3);
  for (Index f = 0; f < mesh.num_faces(); ++f) {
    const Index source = face_order[static_cast<std::size_t>(f)];
    const Index turn = rotate_corners ? f % 3 : 0;
    for (int k = 0; k < 3; ++k)
      out.mesh.F(f, k) = out.new_index[static_cast<std::size_t>(mesh.F(source, (k + turn) % 3))];
  }
  return out;
}

Mesh vertex_clustered(const Mesh& mesh, double cell) {
  std::map<std::array<long long, 3>, int> cluster_of_cell;
  std::vector<int> cluster(static_cast<std::size_t>(mesh.num_vertices()));
  std::vector<Eigen::Vector3d> sum;
  std::vector<int> count;
  for (Index v = 0; v < mesh.num_vertices(); ++v) {
    std::array<long long, 3> key{};
    for (int k = 0; k < 3; ++k)
      key[static_cast<std::size_t>(k)] = static_cast<long long>(std::floor(mesh.V(v, k) / cell));
    const auto [it, added] = cluster_of_cell.emplace(key, static_cast<int>(sum.size()));
    if (added) {
      sum.emplace_back(Eigen::Vector3d::Zero());
      count.push_back(0);
    }
    cluster[static_cast<std::size_t>(v)] = it->second;
    sum[static_cast<std::size_t>(it->second)] += mesh.V.row(v).transpose();
    ++count[static_cast<std::size_t>(it->second)];
  }
  std::vector<Eigen::Vector3d> points;
  for (std::size_t c = 0; c < sum.size(); ++c) points.push_back(sum[c] / count[c]);
  std::vector<Eigen::Vector3i> triangles;
  std::set<std::array<int, 3>> seen;
  for (Index f = 0; f < mesh.num_faces(); ++f) {
    const Eigen::Vector3i t(cluster[static_cast<std::size_t>(mesh.F(f, 0))],
                            cluster[static_cast<std::size_t>(mesh.F(f, 1))],
                            cluster[static_cast<std::size_t>(mesh.F(f, 2))]);
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) continue;
    std::array<int, 3> key{t[0], t[1], t[2]};
    std::sort(key.begin(), key.end());
    if (seen.insert(key).second) triangles.push_back(t);
  }
  // Drop the clusters no face uses; the others are numbered in the order faces first use them.
  std::vector<int> remap(points.size(), -1);
  std::vector<Eigen::Vector3d> used;
  for (auto& t : triangles)
    for (int k = 0; k < 3; ++k) {
      int& r = remap[static_cast<std::size_t>(t[k])];
      if (r < 0) {
        r = static_cast<int>(used.size());
        used.push_back(points[static_cast<std::size_t>(t[k])]);
      }
      t[k] = r;
    }
  return from_lists(used, triangles);
}

Mesh icosphere(double radius, int levels) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Eigen::Vector3d> p = {{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
                                    {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
  std::vector<Eigen::Vector3i> f = {{0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                                    {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                                    {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
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
  grid_triangles(
      along, around, [&](int i, int j) { return i * around + j % around; }, f);
  for (auto& tri : f) std::swap(tri[1], tri[2]);
  return from_lists(p, f);
}

Mesh torus(double R, double r, int around, int tube) {
  return elliptic_torus(R, r, r, around, tube);
}

Mesh elliptic_torus(double R, double a, double b, int around, int tube) {
  std::vector<Eigen::Vector3d> p;
  for (int i = 0; i < around; ++i) {
    const double phi = 2 * M_PI * i / around;
    for (int j = 0; j < tube; ++j) {
      const double theta = 2 * M_PI * j / tube;
      const double rho = R + a * std::cos(theta);
      p.emplace_back(rho * std::cos(phi), rho * std::sin(phi), b * std::sin(theta));
    }
  }
  std::vector<Eigen::Vector3i> f;
  grid_triangles(
      around, tube, [&](int i, int j) { return (i % around) * tube + j % tube; }, f);
  return from_lists(p, f);
}

Mesh height_field(double half, int n, const std::function<double(double, double)>& height) {
  std::vector<Eigen::Vector3d> p;
  for (int i = 0; i <= n; ++i) {
    for (int j = 0; j <= n; ++j) {
      const double x = -half + 2 * half * i / n, y = -half + 2 * half * j / n;
      p.emplace_back(x, y, height(x, y));
    }
  }
  std::vector<Eigen::Vector3i> f;
  grid_triangles(
      n, n, [&](int i, int j) { return i * (n + 1) + j; }, f);
  return from_lists(p, f);
}

Mesh rounded_cube(double core, double radius, int n) {
  // Lattice points (i, j, k) in [0, n]^3 on the cube's surface, welded by their integer key.
  std::map<std::array<int, 3>, int> index;
  std::vector<Eigen::Vector3d> p;
  const auto vertex = [&](std::array<int, 3> key) {
    const auto [it, added] = index.emplace(key, static_cast<int>(p.size()));
    if (added) {
      const Eigen::Vector3d x =
          (core + radius) * (Eigen::Vector3d(key[0], key[1], key[2]) * 2.0 / n - Eigen::Vector3d::Ones());
      const Eigen::Vector3d inner = x.cwiseMax(-core).cwiseMin(core);
      p.push_back(inner + radius * (x - inner).normalized());
    }
    return it->second;
  };
  std::vector<Eigen::Vector3i> f;
  for (int d = 0; d < 3; ++d) {
    const int u = (d + 1) % 3, v = (d + 2) % 3;  // e_u x e_v = e_d
    for (const int side : {0, n}) {
      for (int i = 0; i < n; ++i) {
        for (int j = 0; j < n; ++j) {
          std::array<int, 4> q;
          const int corner[4][2] = {{i, j}, {i + 1, j}, {i + 1, j + 1}, {i, j + 1}};
          for (int c = 0; c < 4; ++c) {
            std::array<int, 3> key{};
            key[d] = side, key[u] = corner[c][0], key[v] = corner[c][1];
            q[c] = vertex(key);
          }
          if (side == 0) std::swap(q[1], q[3]);  // the -e_d face looks the other way
          f.emplace_back(q[0], q[1], q[2]);
          f.emplace_back(q[0], q[2], q[3]);
        }
      }
    }
  }
  return from_lists(p, f);
}

Mesh roof(int n, bool across) {
  Mesh mesh;
  mesh.V.resize((n + 1) * (n + 1), 3);
  auto at = [n](int i, int j) { return static_cast<Index>(j * (n + 1) + i); };
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const double x = static_cast<double>(i) / n, y = static_cast<double>(j) / n;
      mesh.V.row(at(i, j)) << x, y, -std::abs(x - y) / 2;
    }
  mesh.F.resize(2 * n * n, 3);
  Index f = 0;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      if (across) {
        mesh.F.row(f++) << at(i, j), at(i + 1, j), at(i, j + 1);
        mesh.F.row(f++) << at(i + 1, j), at(i + 1, j + 1), at(i, j + 1);
      } else {
        mesh.F.row(f++) << at(i, j), at(i + 1, j), at(i + 1, j + 1);
        mesh.F.row(f++) << at(i, j), at(i + 1, j + 1), at(i, j + 1);
      }
    }
  return mesh;
}

Mesh saddle(double half, int n) {
  return height_field(half, n, [](double x, double y) { return 0.5 * (x * x - y * y); });
}

Mesh bowtie() {
  Mesh mesh;
  mesh.V.resize(5, 3);
  mesh.V << 0, 0, 0, 1, 0, 0, 0, 1, 0, -1, 0, 0, 0, -1, 0;
  mesh.F.resize(2, 3);
  mesh.F << 0, 1, 2, 0, 3, 4;
  return mesh;
}

namespace {

// perforated_plate with each cell cut into sx x sy quads (x by y).
Mesh perforated_plate_lattice(int holes, int sx, int sy, double thickness, bool bottom) {
  const int cells = 2 * holes + 1, nx = cells * sx, ny = cells * sy;  // (nx + 1) x (ny + 1) points
  std::vector<Eigen::Vector3d> p;
  for (int layer = 0; layer < 2; ++layer) {  // 0: bottom (z = 0), 1: top (z = thickness)
    for (int i = 0; i <= nx; ++i) {
      for (int j = 0; j <= ny; ++j) p.emplace_back(double(i) / sx, double(j) / sy, layer * thickness);
    }
  }
  auto index = [&](int layer, int i, int j) { return layer * (nx + 1) * (ny + 1) + i * (ny + 1) + j; };
  auto solid = [&](int i, int j) {  // sub-quad (i, j) of the lattice is material
    return i >= 0 && j >= 0 && i < nx && j < ny && !((i / sx) % 2 == 1 && (j / sy) % 2 == 1);
  };
  std::vector<Eigen::Vector3i> f;
  auto quad = [&](int a, int b, int c, int d) {  // counter-clockwise seen from outside
    f.emplace_back(a, b, c);
    f.emplace_back(a, c, d);
  };
  for (int i = 0; i < nx; ++i) {
    for (int j = 0; j < ny; ++j) {
      if (!solid(i, j)) continue;
      quad(index(1, i, j), index(1, i + 1, j), index(1, i + 1, j + 1), index(1, i, j + 1));
      if (bottom) quad(index(0, i, j), index(0, i, j + 1), index(0, i + 1, j + 1), index(0, i + 1, j));
      // A wall on each side whose neighbour is empty; (a -> b) runs counter-clockwise around
      // the sub-quad seen from above, so the wall (a_bottom, b_bottom, b_top, a_top) faces out.
      const int corner[4][2] = {{i, j}, {i + 1, j}, {i + 1, j + 1}, {i, j + 1}};
      const int neighbour[4][2] = {{i, j - 1}, {i + 1, j}, {i, j + 1}, {i - 1, j}};
      for (int side = 0; side < 4; ++side) {
        if (solid(neighbour[side][0], neighbour[side][1])) continue;
        const int* a = corner[side];
        const int* b = corner[(side + 1) % 4];
        quad(index(0, a[0], a[1]), index(0, b[0], b[1]), index(1, b[0], b[1]), index(1, a[0], a[1]));
      }
    }
  }
  // Drop lattice points no face uses (inside the holes), keeping the order of the others.
  std::vector<int> remap(p.size(), -1);
  for (const auto& t : f) {
    for (int k = 0; k < 3; ++k) remap[static_cast<std::size_t>(t[k])] = 0;
  }
  std::vector<Eigen::Vector3d> used;
  for (std::size_t v = 0; v < p.size(); ++v) {
    if (remap[v] == 0) {
      remap[v] = static_cast<int>(used.size());
      used.push_back(p[v]);
    }
  }
  for (auto& t : f) {
    for (int k = 0; k < 3; ++k) t[k] = remap[static_cast<std::size_t>(t[k])];
  }
  return from_lists(used, f);
}

}  // namespace

Mesh perforated_plate(int holes, int subdivisions, double thickness, bool bottom) {
  return perforated_plate_lattice(holes, subdivisions, subdivisions, thickness, bottom);
}

Mesh sliver_plate(int holes, int slivers, double thickness, double jitter, unsigned seed) {
  Mesh plate = perforated_plate_lattice(holes, slivers, 1, thickness, true);
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> uniform(-jitter / slivers, jitter / slivers);
  for (Index v = 0; v < plate.num_vertices(); ++v) {
    const double x = plate.V(v, 0) * slivers;
    const bool on_cell_line = std::lround(x) % slivers == 0 && std::abs(x - std::round(x)) < 1e-9;
    const double shift = uniform(random);  // drawn for every vertex: the same stream for any jitter
    if (!on_cell_line) plate.V(v, 0) += shift;
  }
  return plate;
}

Mesh with_random_faces_removed(const Mesh& mesh, Index count, unsigned seed) {
  std::vector<Index> order(static_cast<std::size_t>(mesh.num_faces()));
  for (std::size_t f = 0; f < order.size(); ++f) order[f] = static_cast<Index>(f);
  std::mt19937 random(seed);
  std::shuffle(order.begin(), order.end(), random);
  std::vector<char> removed(order.size(), 0);
  for (Index k = 0; k < std::min(count, mesh.num_faces()); ++k) removed[static_cast<std::size_t>(order[k])] = 1;
  Mesh out;
  out.V = mesh.V;
  out.F.resize(mesh.num_faces() - std::min(count, mesh.num_faces()), 3);
  Index row = 0;
  for (Index f = 0; f < mesh.num_faces(); ++f) {
    if (!removed[static_cast<std::size_t>(f)]) out.F.row(row++) = mesh.F.row(f);
  }
  return out;
}

Mesh noisy_scan(const Mesh& mesh, double normal_noise, double tangential_jitter, unsigned seed) {
  const Topology topology = build_topology(mesh.F, mesh.num_vertices());
  const double edge = mean_edge_length(mesh.V, topology);
  const Vertices N = vertex_normals(mesh.V, mesh.F);
  std::mt19937 random(seed);
  std::normal_distribution<double> gaussian(0.0, normal_noise * edge);
  std::uniform_real_distribution<double> uniform(-tangential_jitter * edge, tangential_jitter * edge);
  Mesh out = mesh;
  for (Index v = 0; v < mesh.num_vertices(); ++v) {
    const Eigen::Vector3d n = N.row(v).transpose(), t1 = n.unitOrthogonal(), t2 = n.cross(t1);
    const double along_normal = gaussian(random), along_t1 = uniform(random), along_t2 = uniform(random);
    out.V.row(v) += (along_normal * n + along_t1 * t1 + along_t2 * t2).transpose();
  }
  return out;
}

}  // namespace vertexflow::test
