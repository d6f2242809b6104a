#include "cad_parts.h"

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_face_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

#include <Eigen/Core>

#include <cmath>
#include <list>
#include <numbers>
#include <random>
#include <stdexcept>
#include <vector>

namespace vertexflow::test {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using VertexBase = CGAL::Triangulation_vertex_base_with_info_2<int, Kernel>;
using FaceInfoBase = CGAL::Triangulation_face_base_with_info_2<int, Kernel>;  // nesting level
using FaceBase = CGAL::Constrained_triangulation_face_base_2<Kernel, FaceInfoBase>;
using Tds = CGAL::Triangulation_data_structure_2<VertexBase, FaceBase>;
using Cdt = CGAL::Constrained_Delaunay_triangulation_2<Kernel, Tds, CGAL::Exact_predicates_tag>;

using Loop = std::vector<Eigen::Vector2d>;  // counter-clockwise

int circle_segments(double radius, double tolerance) {
  const double half_angle = std::acos(std::max(-1.0, 1.0 - tolerance / radius));
  return std::max(6, static_cast<int>(std::ceil(std::numbers::pi / half_angle)));
}

void add_arc(Loop& loop, const Eigen::Vector2d& centre, double radius, double from, double to, int segments,
             bool last_too) {
  for (int k = 0; k < segments + (last_too ? 1 : 0); ++k) {
    const double a = from + (to - from) * k / segments;
    loop.emplace_back(centre + radius * Eigen::Vector2d(std::cos(a), std::sin(a)));
  }
}

// Nesting levels by flood fill from the infinite face across constrained edges: faces at an odd
// level are inside the material (between the outline and the holes).
void mark_nesting(Cdt& cdt) {
  for (auto f = cdt.all_faces_begin(); f != cdt.all_faces_end(); ++f) f->info() = -1;
  std::list<Cdt::Edge> borders;
  const auto fill = [&](Cdt::Face_handle start, int level) {
    std::list<Cdt::Face_handle> queue{start};
    while (!queue.empty()) {
      const Cdt::Face_handle f = queue.front();
      queue.pop_front();
      if (f->info() != -1) continue;
      f->info() = level;
      for (int i = 0; i < 3; ++i) {
        const Cdt::Face_handle n = f->neighbor(i);
        if (n->info() != -1) continue;
        if (cdt.is_constrained(Cdt::Edge(f, i)))
          borders.emplace_back(f, i);
        else
          queue.push_back(n);
      }
    }
  };
  fill(cdt.infinite_face(), 0);
  while (!borders.empty()) {
    const Cdt::Edge e = borders.front();
    borders.pop_front();
    const Cdt::Face_handle n = e.first->neighbor(e.second);
    if (n->info() == -1) fill(n, e.first->info() + 1);
  }
}

}  // namespace

Mesh cad_perforated_plate(const CadPlateOptions& o) {
  using Outline = CadPlateOptions::Outline;
  // The outline, counter-clockwise: a rectangle keeps only its four corners, as exporters do.
  Loop outline;
  if (o.outline == Outline::Rectangle) {
    const double w = o.width / 2, h = o.height / 2;
    outline = {{-w, -h}, {w, -h}, {w, h}, {-w, h}};
  } else {
    add_arc(outline, Eigen::Vector2d::Zero(), o.width / 2, 0, 2 * std::numbers::pi, o.outline_segments, false);
  }
  const auto inside_outline = [&](const Eigen::Vector2d& c, double r) {
    if (o.outline == Outline::Rectangle)
      return std::abs(c.x()) + r <= o.width / 2 && std::abs(c.y()) + r <= o.height / 2;
    // The polygon's inradius, not the circle's.
    return c.norm() + r <= o.width / 2 * std::cos(std::numbers::pi / o.outline_segments);
  };

  // Holes by rejection sampling; a slot's bounding circle keeps slots apart.
  std::mt19937 random(o.seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double slot_half = o.hole == CadPlateOptions::Hole::Slot ? o.slot_length / 2 : 0.0;
  struct Placed {
    Eigen::Vector2d centre;
    double radius, reach;
    bool along_x;
  };
  std::vector<Placed> placed;
  for (int attempt = 0; static_cast<int>(placed.size()) < o.holes; ++attempt) {
    if (attempt > 1000000) throw std::runtime_error("cad_perforated_plate: the holes do not fit");
    const double r = o.min_radius + (o.max_radius - o.min_radius) * unit(random);
    const Eigen::Vector2d c(o.width * (unit(random) - 0.5), o.height * (unit(random) - 0.5));
    const bool along_x = unit(random) < 0.5;
    const double reach = r + slot_half;
    if (!inside_outline(c, reach + o.spacing)) continue;
    bool free = true;
    for (const Placed& p : placed) free = free && (p.centre - c).norm() >= p.reach + reach + o.spacing;
    if (free) placed.push_back({c, r, reach, along_x});
  }
  std::vector<Loop> holes;
  for (const Placed& p : placed) {
    Loop loop;
    const int n = circle_segments(p.radius, o.chord_tolerance);
    if (slot_half == 0) {
      add_arc(loop, p.centre, p.radius, 0, 2 * std::numbers::pi, n, false);
    } else {  // two half circles joined by straight sides without intermediate points
      const double turn = p.along_x ? 0.0 : std::numbers::pi / 2;
      const Eigen::Vector2d axis(std::cos(turn), std::sin(turn));
      const int half = std::max(3, n / 2);
      add_arc(loop, p.centre + slot_half * axis, p.radius, turn - std::numbers::pi / 2, turn + std::numbers::pi / 2,
              half, true);
      add_arc(loop, p.centre - slot_half * axis, p.radius, turn + std::numbers::pi / 2, turn + 3 * std::numbers::pi / 2,
              half, true);
    }
    holes.push_back(std::move(loop));
  }

  // One face: the constrained Delaunay triangulation of the loops, without Steiner points on a
  // flat plate.
  std::vector<Eigen::Vector2d> points;
  std::vector<std::vector<int>> loops;  // indices into points; loops[0] the outline
  Cdt cdt;
  const auto insert_loop = [&](const Loop& loop) {
    std::vector<int> ids;
    std::vector<Cdt::Vertex_handle> handles;
    for (const Eigen::Vector2d& p : loop) {
      const Cdt::Vertex_handle h = cdt.insert(Kernel::Point_2(p.x(), p.y()));
      h->info() = static_cast<int>(points.size());
      ids.push_back(static_cast<int>(points.size()));
      points.push_back(p);
      handles.push_back(h);
    }
    for (std::size_t k = 0; k < handles.size(); ++k)
      cdt.insert_constraint(handles[k], handles[(k + 1) % handles.size()]);
    loops.push_back(std::move(ids));
  };
  insert_loop(outline);
  for (const Loop& hole : holes) insert_loop(hole);
  if (cdt.number_of_vertices() != points.size())
    throw std::runtime_error("cad_perforated_plate: two loop points coincide");
  if (o.bend_radius > 0) {
    // A curved face's interior points: a grid in the face's parameters (arc length across the
    // bend, length along the axis), kept where it is in the material and clear of every rim.
    const double column = std::sqrt(8 * o.bend_radius * o.chord_tolerance);
    const double row = o.row_spacing_factor * column;
    const double clearance = std::max(o.spacing / 2, column / 4);
    for (double u = -o.width / 2 + column / 2; u < o.width / 2; u += column)
      for (double v = -o.height / 2 + row / 2; v < o.height / 2; v += row) {
        const Eigen::Vector2d c(u, v);
        bool free = inside_outline(c, clearance);
        for (const Placed& p : placed) free = free && (p.centre - c).norm() >= p.reach + clearance;
        if (!free) continue;
        const Cdt::Vertex_handle h = cdt.insert(Kernel::Point_2(u, v));
        h->info() = static_cast<int>(points.size());
        points.push_back(c);
      }
  }
  mark_nesting(cdt);
  std::vector<std::array<int, 3>> cap;
  for (auto f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f)
    if (f->info() % 2 == 1) cap.push_back({f->vertex(0)->info(), f->vertex(1)->info(), f->vertex(2)->info()});

  // Top (z = +t/2, vertices 0..m-1) and bottom (-t/2, m..2m-1) caps, then the walls: the
  // outline's facing out, the holes' facing into the holes.
  const int m = static_cast<int>(points.size());
  std::vector<std::array<int, 3>> faces;
  for (const auto& t : cap) {
    faces.push_back(t);
    faces.push_back({t[0] + m, t[2] + m, t[1] + m});
  }
  for (std::size_t l = 0; l < loops.size(); ++l) {
    const std::vector<int>& ids = loops[l];
    const std::size_t n = ids.size();
    for (std::size_t k = 0; k < n; ++k) {
      int a = ids[k], b = ids[(k + 1) % n];
      if (l == 0) std::swap(a, b);  // the outline runs counter-clockwise: its wall faces out
      faces.push_back({a, b, a + m});
      faces.push_back({b, b + m, a + m});
    }
  }

  // The thickness t = thickness_in_edges * mean edge length, where the walls' edges (t and the
  // diagonals) are part of the mean: a fixed point, reached in a few steps as the fraction is small.
  std::vector<std::array<int, 2>> edges;
  for (const auto& f : faces)
    for (int k = 0; k < 3; ++k)
      if (f[k] < f[(k + 1) % 3]) edges.push_back({f[k], f[(k + 1) % 3]});
  const auto position = [&](int v, double t) -> Eigen::Vector3d {
    const Eigen::Vector2d& p = points[static_cast<std::size_t>(v % m)];
    const double offset = v < m ? t / 2 : -t / 2;
    if (o.bend_radius <= 0) return {p.x(), p.y(), offset};
    const double r = o.bend_radius + offset, angle = p.x() / o.bend_radius;
    return {r * std::sin(angle), p.y(), r * std::cos(angle) - o.bend_radius};
  };
  double t = 1.0;
  for (int step = 0; step < 50; ++step) {
    double sum = 0;
    for (const auto& e : edges) sum += (position(e[0], t) - position(e[1], t)).norm();
    t = o.thickness_in_edges * sum / static_cast<double>(edges.size());
  }

  Mesh mesh;
  mesh.V.resize(2 * m, 3);
  for (int v = 0; v < 2 * m; ++v) mesh.V.row(v) = position(v, t).transpose();
  mesh.F.resize(static_cast<Index>(faces.size()), 3);
  for (std::size_t f = 0; f < faces.size(); ++f)
    mesh.F.row(static_cast<Index>(f)) << faces[f][0], faces[f][1], faces[f][2];
  return mesh;
}

}  // namespace vertexflow::test
