#include "raw_scan.h"

#include "vertexflow/remesh.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <random>
#include <utility>
#include <vector>

namespace vertexflow::test {
namespace {

Eigen::Vector3d centroid(const Mesh& m, Index f) {
  return (m.V.row(m.F(f, 0)) + m.V.row(m.F(f, 1)) + m.V.row(m.F(f, 2))).transpose() / 3.0;
}

// Faces whose centroid lies within `radius` of face `seed`'s centroid, grown from `seed` across
// shared vertices (so a patch never jumps to another sheet of the surface).
std::vector<Index> patch(const Mesh& m, const std::vector<std::vector<Index>>& vertex_faces, Index seed, double radius,
                         std::vector<char>& visited) {
  const Eigen::Vector3d c = centroid(m, seed);
  std::vector<Index> out{seed}, touched{seed};
  visited[static_cast<std::size_t>(seed)] = 1;
  for (std::size_t next = 0; next < out.size(); ++next) {
    for (int k = 0; k < 3; ++k) {
      for (const Index g : vertex_faces[static_cast<std::size_t>(m.F(out[next], k))]) {
        if (visited[static_cast<std::size_t>(g)]) continue;
        visited[static_cast<std::size_t>(g)] = 1;
        touched.push_back(g);
        if ((centroid(m, g) - c).norm() <= radius) out.push_back(g);
      }
    }
  }
  for (const Index g : touched) visited[static_cast<std::size_t>(g)] = 0;
  return out;
}

double log_uniform(std::mt19937& random, double lo, double hi) {
  return std::exp(std::uniform_real_distribution<double>(std::log(lo), std::log(hi))(random));
}

// Each face split into 4 at its edge midpoints; the surface is unchanged.
Mesh subdivided(const Mesh& m) {
  std::map<std::pair<Index, Index>, Index> midpoint;
  std::vector<Eigen::Vector3d> points;
  for (Index v = 0; v < m.num_vertices(); ++v) points.emplace_back(m.V.row(v).transpose());
  const auto middle = [&](Index a, Index b) {
    const auto [it, inserted] = midpoint.emplace(std::minmax(a, b), static_cast<Index>(points.size()));
    if (inserted) points.push_back(0.5 * (points[static_cast<std::size_t>(a)] + points[static_cast<std::size_t>(b)]));
    return it->second;
  };
  Mesh out;
  out.F.resize(4 * m.num_faces(), 3);
  for (Index f = 0; f < m.num_faces(); ++f) {
    const Index a = m.F(f, 0), b = m.F(f, 1), c = m.F(f, 2);
    const Index ab = middle(a, b), bc = middle(b, c), ca = middle(c, a);
    out.F.row(4 * f) << a, ab, ca;
    out.F.row(4 * f + 1) << ab, b, bc;
    out.F.row(4 * f + 2) << ca, bc, c;
    out.F.row(4 * f + 3) << ab, bc, ca;
  }
  out.V.resize(static_cast<Index>(points.size()), 3);
  for (std::size_t v = 0; v < points.size(); ++v) out.V.row(static_cast<Index>(v)) = points[v].transpose();
  return out;
}

}  // namespace

RawScan make_raw_scan(const Mesh& input, const RawScanOptions& options) {
  Mesh clean = input;
  for (int s = 0; s < options.subdivisions; ++s) clean = subdivided(clean);
  RawScan out;
  double area = 0;
  for (Index f = 0; f < clean.num_faces(); ++f) area += face_area(clean.V, clean.F, f);
  const double L = edge_length_for_vertex_count(area, options.target_vertices);
  out.target_edge = L;
  double input_edge = 0;
  for (Index f = 0; f < clean.num_faces(); ++f)
    for (int k = 0; k < 3; ++k)
      input_edge += (clean.V.row(clean.F(f, k)) - clean.V.row(clean.F(f, (k + 1) % 3))).norm();
  input_edge /= 3.0 * static_cast<double>(clean.num_faces());

  std::vector<std::vector<Index>> vertex_faces(static_cast<std::size_t>(clean.num_vertices()));
  for (Index f = 0; f < clean.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) vertex_faces[static_cast<std::size_t>(clean.F(f, k))].push_back(f);
  std::mt19937 random(options.seed);
  std::uniform_int_distribution<Index> any_face(0, clean.num_faces() - 1);
  std::uniform_real_distribution<double> unit(0.0, 1.0);

  // Holes. hole_of[f] = the hole that removed face f, -1 if kept.
  std::vector<int> hole_of(static_cast<std::size_t>(clean.num_faces()), -1);
  std::vector<char> visited(hole_of.size(), 0);
  std::vector<char> sliver_hole;
  for (int h = 0; h < options.holes; ++h) {
    Index seed = any_face(random);
    while (hole_of[static_cast<std::size_t>(seed)] >= 0) seed = any_face(random);
    const double radius = L * log_uniform(random, options.hole_radius_min, options.hole_radius_max);
    for (const Index f : patch(clean, vertex_faces, seed, radius, visited))
      if (hole_of[static_cast<std::size_t>(f)] < 0) hole_of[static_cast<std::size_t>(f)] = h;
    sliver_hole.push_back(unit(random) < options.sliver_hole_share);
  }
  out.holes = options.holes;

  std::vector<Eigen::Vector3d> points;
  for (Index v = 0; v < clean.num_vertices(); ++v) points.emplace_back(clean.V.row(v).transpose());
  std::vector<std::array<Index, 3>> faces;
  std::map<std::pair<Index, Index>, int> removed_edge_hole;  // directed edge of a removed face -> its hole
  for (Index f = 0; f < clean.num_faces(); ++f) {
    const int h = hole_of[static_cast<std::size_t>(f)];
    if (h < 0) {
      faces.push_back({clean.F(f, 0), clean.F(f, 1), clean.F(f, 2)});
    } else {
      for (int k = 0; k < 3; ++k) removed_edge_hole[{clean.F(f, k), clean.F(f, (k + 1) % 3)}] = h;
    }
  }

  // Rim slivers: a kept face's edge a -> b whose twin b -> a was removed borders a hole; the
  // sliver (b, a, c) has c just off the midpoint, on the hole's side ((b - a) x n points away
  // from the kept face).
  const std::size_t kept_faces = faces.size();
  for (std::size_t i = 0; i < kept_faces; ++i) {
    const auto face = faces[i];
    for (int k = 0; k < 3; ++k) {
      const Index a = face[static_cast<std::size_t>(k)], b = face[static_cast<std::size_t>((k + 1) % 3)];
      const auto twin = removed_edge_hole.find({b, a});
      if (twin == removed_edge_hole.end() || !sliver_hole[static_cast<std::size_t>(twin->second)]) continue;
      if (unit(random) >= 0.7) continue;
      const Eigen::Vector3d pa = points[static_cast<std::size_t>(a)], pb = points[static_cast<std::size_t>(b)];
      const Eigen::Vector3d n =
          (pb - pa).cross(points[static_cast<std::size_t>(face[static_cast<std::size_t>((k + 2) % 3)])] - pa);
      const Eigen::Vector3d away = (pb - pa).cross(n).normalized();
      const double offset = log_uniform(random, 1e-5, 3e-2) * (pb - pa).norm();
      points.push_back(0.5 * (pa + pb) + offset * away);
      faces.push_back({b, a, static_cast<Index>(points.size() - 1)});
      ++out.slivers;
    }
  }

  // Floating pieces.
  for (int p = 0; p < options.pieces; ++p) {
    const Index seed = any_face(random);
    const double size = L * log_uniform(random, options.piece_size_min, options.piece_size_max);
    const Eigen::Vector3d n = face_normal(clean.V, clean.F, seed).normalized();
    const double lift = L * (0.3 + 1.7 * unit(random)) * (unit(random) < 0.5 ? -1.0 : 1.0);
    const Eigen::Vector3d shift = lift * n;
    if (size < L) ++out.pieces_below_target;
    if (size < input_edge) {
      // One or two random triangles of about `size` across (scanner speckle).
      const Eigen::Vector3d c = centroid(clean, seed) + shift;
      const Eigen::Vector3d t1 = n.unitOrthogonal(), t2 = n.cross(t1);
      const int triangles = unit(random) < 0.5 ? 1 : 2;
      const Index first = static_cast<Index>(points.size());
      for (int k = 0; k < triangles + 2; ++k) {
        const double angle = 6.283185307179586 * (k + 0.3 * unit(random)) / (triangles + 2);
        points.push_back(c +
                         0.5 * size * (std::cos(angle) * t1 + std::sin(angle) * t2 + 0.2 * (unit(random) - 0.5) * n));
      }
      faces.push_back({first, first + 1, first + 2});
      if (triangles == 2) faces.push_back({first, first + 2, first + 3});
    } else {
      std::map<Index, Index> copy;
      for (const Index f : patch(clean, vertex_faces, seed, 0.5 * size, visited)) {
        std::array<Index, 3> face{};
        for (int k = 0; k < 3; ++k) {
          const Index v = clean.F(f, k);
          auto [it, inserted] = copy.emplace(v, static_cast<Index>(points.size()));
          // Crumpled like scanner speckle: each vertex off the copied surface by up to half an
          // input edge.
          if (inserted) points.push_back(clean.V.row(v).transpose() + shift + input_edge * (unit(random) - 0.5) * n);
          face[static_cast<std::size_t>(k)] = it->second;
        }
        faces.push_back(face);
      }
    }
    ++out.pieces;
  }

  // Vertices only the removed faces used are dropped; the others keep their order.
  std::vector<Index> index(points.size(), -1);
  for (const auto& face : faces)
    for (const Index v : face) index[static_cast<std::size_t>(v)] = 0;
  Index count = 0;
  for (Index& i : index)
    if (i == 0) i = count++;
  out.mesh.V.resize(count, 3);
  for (std::size_t v = 0; v < points.size(); ++v)
    if (index[v] >= 0) out.mesh.V.row(index[v]) = points[v].transpose();
  out.mesh.F.resize(static_cast<Index>(faces.size()), 3);
  for (std::size_t f = 0; f < faces.size(); ++f)
    for (int k = 0; k < 3; ++k)
      out.mesh.F(static_cast<Index>(f), k) = index[static_cast<std::size_t>(faces[f][static_cast<std::size_t>(k)])];
  return out;
}

}  // namespace vertexflow::test
