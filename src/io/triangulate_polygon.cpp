// Triangulation of the polygons of OBJ, PLY and OFF files.
//
// Quads (the common case, e.g. quad-dominant CAD and subdivision meshes) are split along the
// diagonal that gives two triangles facing the polygon's normal; for a convex quad both do,
// and the one with the better worse triangle is taken. Larger polygons are projected into the
// plane orthogonal to their Newell normal and triangulated there in O(n log n): CGAL checks that
// the projection is simple and splits it into y-monotone pieces, a linear sweep triangulates
// each piece, and edge flips (bounded in number, see make_delaunay) then turn the result into
// the polygon's constrained Delaunay triangulation, so that the triangles are as well shaped as
// the corners allow.
//
// Inserting the corners and edges into CGAL's Constrained_Delaunay_triangulation_2, as before,
// is quadratic: it inserts an edge by removing every Delaunay edge the edge crosses, and the
// long edges of a comb with long leaning teeth cross O(n) of them each (issue 12: 31 s for
// 100k corners).
#include "io_internal.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Partition_traits_2.h>
#include <CGAL/Polygon_2_algorithms.h>
#include <CGAL/partition_2.h>
#include <CGAL/property_map.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cstdint>
#include <tuple>
#include <utility>

namespace vertexflow::io_detail {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point2 = Kernel::Point_2;

Eigen::Vector3d point(const double* xyz, Index v) {
  const std::size_t i = 3 * static_cast<std::size_t>(v);
  return {xyz[i], xyz[i + 1], xyz[i + 2]};
}

// Newell's normal: robust for non-planar and non-convex polygons (unnormalised).
Eigen::Vector3d newell_normal(const double* xyz, const Index* c, std::size_t n) {
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < n; ++i) normal += point(xyz, c[i]).cross(point(xyz, c[(i + 1) % n]));
  return normal;
}

void fan(const Index* c, std::size_t n, std::vector<Index>& out) {
  for (std::size_t i = 1; i + 1 < n; ++i) out.insert(out.end(), {c[0], c[i], c[i + 1]});
}

double radius_ratio(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const double x = (b - c).norm(), y = (c - a).norm(), z = (a - b).norm();
  const double denominator = x * y * z;
  return denominator > 0 ? (y + z - x) * (z + x - y) * (x + y - z) / denominator : 0.0;
}

bool triangulate_quad(const double* xyz, const Index* c, const Eigen::Vector3d& normal, EdgeSet& edges,
                      std::vector<Index>& out) {
  const Eigen::Vector3d p[4] = {point(xyz, c[0]), point(xyz, c[1]), point(xyz, c[2]), point(xyz, c[3])};
  auto faces_normal = [&](int i, int j, int k) { return (p[j] - p[i]).cross(p[k] - p[i]).dot(normal) > 0; };
  // Diagonal 0-2 gives (0,1,2), (0,2,3); diagonal 1-3 gives (0,1,3), (1,2,3).
  const bool valid02 = faces_normal(0, 1, 2) && faces_normal(0, 2, 3);
  const bool valid13 = faces_normal(0, 1, 3) && faces_normal(1, 2, 3);
  if (!valid02 && !valid13) {
    fan(c, 4, out);
    return false;
  }
  bool use02 = valid02;
  if (valid02 && valid13) {
    const bool exists02 = edges.count(edge_key(c[0], c[2])) > 0;
    const bool exists13 = edges.count(edge_key(c[1], c[3])) > 0;
    if (exists02 != exists13) {
      use02 = exists13;
    } else {
      const double q02 = std::min(radius_ratio(p[0], p[1], p[2]), radius_ratio(p[0], p[2], p[3]));
      const double q13 = std::min(radius_ratio(p[0], p[1], p[3]), radius_ratio(p[1], p[2], p[3]));
      use02 = q02 >= q13;
    }
  }
  if (use02) {
    out.insert(out.end(), {c[0], c[1], c[2], c[0], c[2], c[3]});
    edges.insert(edge_key(c[0], c[2]));
  } else {
    out.insert(out.end(), {c[0], c[1], c[3], c[1], c[2], c[3]});
    edges.insert(edge_key(c[1], c[3]));
  }
  return true;
}

// The order of CGAL's y-monotone partition sweep (Less_yx_2): by y, ties by x.
bool below(const Point2& a, const Point2& b) {
  return a.y() < b.y() || (a.y() == b.y() && a.x() < b.x());
}

// Appends (as indices into `p`) the triangles of one counter-clockwise piece of the partition
// by the stack sweep for monotone polygons (de Berg et al., Computational Geometry, 3.3), in
// linear time; CGAL partitions into monotone pieces but does not triangulate them. A triangle
// may be flat when a corner lies on the line of two others; the flips below remove those.
// Returns false if the piece is not monotone in the sweep order.
bool triangulate_monotone(const std::vector<Point2>& p, const std::vector<std::uint32_t>& piece,
                          std::vector<std::uint32_t>& triangles) {
  const std::size_t m = piece.size();
  auto lower = [&](std::uint32_t a, std::uint32_t b) { return below(p[a], p[b]); };
  std::size_t top = 0;
  for (std::size_t i = 1; i < m; ++i) {
    if (lower(piece[top], piece[i])) top = i;
  }
  // Counter-clockwise from the top, the boundary runs down the left chain to the bottom and
  // back up the right chain. Merge the two chains into sweep order (top first).
  struct Corner {
    std::uint32_t v;
    bool left;
  };
  std::vector<Corner> sweep{{piece[top], true}};
  sweep.reserve(m);
  std::size_t l = (top + 1) % m, r = (top + m - 1) % m;
  while (l != r) {
    if (lower(piece[r], piece[l])) {
      sweep.push_back({piece[l], true});
      l = (l + 1) % m;
    } else {
      sweep.push_back({piece[r], false});
      r = (r + m - 1) % m;
    }
  }
  sweep.push_back({piece[l], true});  // the bottom
  for (std::size_t i = 1; i < m; ++i) {
    if (!lower(sweep[i].v, sweep[i - 1].v)) return false;  // a chain turns back: not monotone
  }

  auto orientation = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    return CGAL::orientation(p[a], p[b], p[c]);
  };
  // Triangle (u, s, t) for consecutive stacked corners s above t, counter-clockwise.
  auto add_fan_triangle = [&](std::uint32_t u, std::uint32_t s, std::uint32_t t, bool stack_on_left) {
    if (stack_on_left)
      triangles.insert(triangles.end(), {u, s, t});
    else
      triangles.insert(triangles.end(), {u, t, s});
  };
  // The stack holds the corners swept but not yet cut off: a reflex (or straight) chain.
  std::vector<Corner> stack{sweep[0], sweep[1]};
  for (std::size_t j = 2; j + 1 < m; ++j) {
    const Corner u = sweep[j];
    if (u.left != stack.back().left) {
      // u faces the whole chain: cut it off with a fan.
      for (std::size_t k = 0; k + 1 < stack.size(); ++k)
        add_fan_triangle(u.v, stack[k].v, stack[k + 1].v, stack.back().left);
      const Corner last = stack.back();
      stack.assign({last, u});
    } else {
      // Same chain: cut off triangles while the stacked corner next to u is convex.
      Corner last = stack.back();
      stack.pop_back();
      while (!stack.empty()) {
        const std::uint32_t s = stack.back().v;
        const std::array<std::uint32_t, 3> t = u.left ? std::array{s, last.v, u.v} : std::array{u.v, last.v, s};
        if (orientation(t[0], t[1], t[2]) != CGAL::LEFT_TURN) break;
        triangles.insert(triangles.end(), t.begin(), t.end());
        last = stack.back();
        stack.pop_back();
      }
      stack.push_back(last);
      stack.push_back(u);
    }
  }
  for (std::size_t k = 0; k + 1 < stack.size(); ++k)
    add_fan_triangle(sweep[m - 1].v, stack[k].v, stack[k + 1].v, stack.back().left);
  return true;
}

// Flips the diagonals of a triangulation of a counter-clockwise simple polygon, whose corners
// are the indices i into `p` with a successor next_corner[i] (its edges run from i to it), until
// the triangulation is constrained Delaunay and no triangle is flat. Returns false unless the
// triangles cover the polygon exactly once with positive orientation. Hand-written because
// CGAL's triangulations cannot start from a given one, and building theirs was the quadratic part.
bool make_delaunay(const std::vector<Point2>& p, const std::vector<std::uint32_t>& next_corner, std::size_t corners,
                   std::vector<std::uint32_t>& v) {
  if (v.size() != 3 * (corners - 2)) return false;
  auto next = [](std::size_t h) { return h % 3 == 2 ? h - 2 : h + 1; };
  // Half-edge h of triangle h / 3 runs from v[h] to v[next(h)]. Pair each with its opposite by
  // sorting; an unpaired one must be a polygon edge. Then every edge cancels except the
  // polygon's own, once each, so the positive triangles cover the polygon exactly once.
  std::vector<std::tuple<std::uint32_t, std::uint32_t, std::uint32_t>> undirected(v.size());
  for (std::size_t h = 0; h < v.size(); ++h) {
    undirected[h] = {std::min(v[h], v[next(h)]), std::max(v[h], v[next(h)]), static_cast<std::uint32_t>(h)};
  }
  std::sort(undirected.begin(), undirected.end());
  constexpr std::uint32_t kNone = UINT32_MAX;
  std::vector<std::uint32_t> twin(v.size(), kNone);
  std::size_t boundary = 0;
  auto same_edge = [&](std::size_t i, std::size_t j) {
    return j < undirected.size() && std::get<0>(undirected[i]) == std::get<0>(undirected[j]) &&
           std::get<1>(undirected[i]) == std::get<1>(undirected[j]);
  };
  for (std::size_t i = 0; i < undirected.size();) {
    const std::uint32_t h = std::get<2>(undirected[i]);
    if (same_edge(i, i + 1)) {
      const std::uint32_t g = std::get<2>(undirected[i + 1]);
      if (v[h] == v[g] || same_edge(i, i + 2)) return false;  // same direction twice, or three triangles
      twin[h] = g, twin[g] = h;
      i += 2;
    } else {
      if (next_corner[v[h]] != v[next(h)]) return false;  // a gap or fold inside the polygon
      ++boundary;
      i += 1;
    }
  }
  if (boundary != corners) return false;

  std::vector<std::uint32_t> todo;
  for (std::size_t h = 0; h < v.size(); ++h) {
    if (twin[h] != kNone && twin[h] > h) todo.push_back(static_cast<std::uint32_t>(h));
  }
  // Lawson's flips reach the constrained Delaunay triangulation, usually in O(n) flips but in
  // O(n^2) at worst; past this budget only flat triangles are still flipped, so the time stays
  // O(n log n) and the triangulation valid, if not quite Delaunay.
  std::size_t budget = 8 * corners;
  while (!todo.empty()) {
    const std::size_t h = todo.back();
    todo.pop_back();
    const std::size_t g = twin[h];
    if (g == kNone) continue;  // flips since it was queued made the slot a polygon edge
    // Triangles (a, b, c) and (b, a, d) share the edge a-b; flipping it gives (a, d, c), (d, b, c).
    const std::size_t hb = next(h), hc = next(hb), ga = next(g), gd = next(ga);
    const Point2 &a = p[v[h]], &b = p[v[hb]], &c = p[v[hc]], &d = p[v[gd]];
    const bool flat = CGAL::collinear(a, b, c) || CGAL::collinear(b, a, d);
    if (!flat && (budget == 0 || CGAL::side_of_oriented_circle(a, b, c, d) != CGAL::ON_POSITIVE_SIDE)) continue;
    if (CGAL::orientation(a, d, c) != CGAL::LEFT_TURN || CGAL::orientation(d, b, c) != CGAL::LEFT_TURN) continue;
    if (!flat) --budget;
    const std::uint32_t va = v[h], vb = v[hb], vc = v[hc], vd = v[gd];
    const std::uint32_t outer_bc = twin[hb], outer_ca = twin[hc], outer_ad = twin[ga], outer_db = twin[gd];
    const std::size_t t1 = h - h % 3, t2 = g - g % 3;
    // Half-edges t1 + 1 and t2 + 2 are the new diagonal.
    v[t1] = va, v[t1 + 1] = vd, v[t1 + 2] = vc;
    v[t2] = vd, v[t2 + 1] = vb, v[t2 + 2] = vc;
    auto link = [&](std::size_t x, std::uint32_t y) {
      twin[x] = y;
      if (y != kNone) twin[y] = static_cast<std::uint32_t>(x);
    };
    link(t1, outer_ad);
    link(t1 + 2, outer_ca);
    link(t2, outer_db);
    link(t2 + 1, outer_bc);
    link(t1 + 1, static_cast<std::uint32_t>(t2 + 2));
    for (const std::size_t x : {t1, t1 + 2, t2, t2 + 1}) {
      if (twin[x] != kNone) todo.push_back(static_cast<std::uint32_t>(x));
    }
  }
  for (std::size_t t = 0; t < v.size(); t += 3) {
    if (CGAL::orientation(p[v[t]], p[v[t + 1]], p[v[t + 2]]) != CGAL::LEFT_TURN) return false;
  }
  return true;
}

bool triangulate_general(const double* xyz, const Index* c, std::size_t n, const Eigen::Vector3d& normal,
                         std::vector<Index>& out) {
  // Project into the plane orthogonal to the normal, with (u, v, normal) right-handed so the
  // polygon's orientation is counter-clockwise in 2D.
  const Eigen::Vector3d w = normal.normalized();
  const Eigen::Vector3d u = w.unitOrthogonal();
  const Eigen::Vector3d v = w.cross(u);
  std::vector<Index> corners(c, c + n);
  std::vector<Point2> p(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d q = point(xyz, c[i]);
    p[i] = Point2(q.dot(u), q.dot(v));
  }
  // Sweep-line test, O(n log n), stopping at the first crossing (a star polygon's edges cross
  // O(n^2) times); coincident corners also make it fail.
  if (!CGAL::is_simple_2(p.begin(), p.end(), Kernel())) return false;
  // Rounding can turn a sliver polygon clockwise after projection; the triangles still face the
  // normal as long as they are counter-clockwise in the plane.
  if (CGAL::orientation_2(p.begin(), p.end(), Kernel()) != CGAL::COUNTERCLOCKWISE) {
    std::reverse(corners.begin(), corners.end());
    std::reverse(p.begin(), p.end());
  }

  // Straight corners (on the line of their neighbours) are left out of the partition, whose
  // sweep mishandles them (CGAL issue 3332), and put back afterwards.
  std::vector<std::uint32_t> bent, next_bent(n, UINT32_MAX), next_corner(n);
  for (std::size_t i = 0; i < n; ++i) {
    next_corner[i] = static_cast<std::uint32_t>((i + 1) % n);
    if (!CGAL::are_strictly_ordered_along_line(p[(i + n - 1) % n], p[i], p[(i + 1) % n]))
      bent.push_back(static_cast<std::uint32_t>(i));
  }
  if (bent.size() < 3) return false;
  for (std::size_t k = 0; k < bent.size(); ++k) next_bent[bent[k]] = bent[(k + 1) % bent.size()];

  using PointMap = CGAL::Pointer_property_map<Point2>::const_type;
  using Traits = CGAL::Partition_traits_2<Kernel, PointMap>;
  std::vector<Traits::Polygon_2> pieces;
  CGAL::y_monotone_partition_2(bent.begin(), bent.end(), std::back_inserter(pieces),
                               Traits(CGAL::make_property_map(std::as_const(p))));
  std::vector<std::uint32_t> triangles, piece;
  triangles.reserve(3 * (n - 2));
  for (const auto& polygon : pieces) {
    piece.assign(polygon.vertices_begin(), polygon.vertices_end());
    if (!triangulate_monotone(p, piece, triangles)) return false;
  }
  if (!make_delaunay(p, next_bent, bent.size(), triangles)) return false;
  if (bent.size() < n) {
    // A triangle on an edge a-b that skips straight corners becomes a fan from its third corner.
    // The fan's first triangle is looked at again: its edge apex-a may skip corners too.
    for (std::size_t t = 0; t < triangles.size();) {
      bool split = false;
      for (std::size_t k = 0; k < 3 && !split; ++k) {
        const std::uint32_t a = triangles[t + k], b = triangles[t + (k + 1) % 3], apex = triangles[t + (k + 2) % 3];
        if (next_bent[a] != b || next_corner[a] == b) continue;
        triangles[t] = a, triangles[t + 1] = next_corner[a], triangles[t + 2] = apex;
        for (std::uint32_t i = next_corner[a]; i != b; i = next_corner[i])
          triangles.insert(triangles.end(), {i, next_corner[i], apex});
        split = true;
      }
      if (!split) t += 3;
    }
    if (!make_delaunay(p, next_corner, n, triangles)) return false;
  }
  for (const std::uint32_t i : triangles) out.push_back(corners[i]);
  return true;
}

}  // namespace

bool triangulate_polygon(const double* xyz, const Index* corners, std::size_t count, EdgeSet& edges,
                         std::vector<Index>& out) {
  const Eigen::Vector3d normal = newell_normal(xyz, corners, count);
  if (!(normal.squaredNorm() > 0)) {
    fan(corners, count, out);
    return false;
  }
  if (count == 4) return triangulate_quad(xyz, corners, normal, edges, out);
  if (triangulate_general(xyz, corners, count, normal, out)) return true;
  fan(corners, count, out);
  return false;
}

}  // namespace vertexflow::io_detail
