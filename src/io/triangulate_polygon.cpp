// Triangulation of the polygons of OBJ, PLY and OFF files.
//
// Quads (the common case, e.g. quad-dominant CAD and subdivision meshes) are split along the
// diagonal that gives two triangles facing the polygon's normal; for a convex quad both do,
// and the one with the better worse triangle is taken. Larger polygons go through CGAL's
// constrained Delaunay triangulation in the polygon's best-fit plane, with inside/outside
// decided by crossing constrained edges, so non-convex polygons are triangulated correctly.
#include "io_internal.h"

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_face_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

#include <Eigen/Geometry>

#include <deque>

namespace vertexflow::io_detail {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using VertexBase = CGAL::Triangulation_vertex_base_with_info_2<Index, Kernel>;
struct FaceInfo {
  int crossings = -1;  // constrained edges crossed from the outside; odd = inside the polygon
};
using FaceBase = CGAL::Constrained_triangulation_face_base_2<
    Kernel, CGAL::Triangulation_face_base_with_info_2<FaceInfo, Kernel>>;
using Cdt = CGAL::Constrained_Delaunay_triangulation_2<
    Kernel, CGAL::Triangulation_data_structure_2<VertexBase, FaceBase>, CGAL::Exact_predicates_tag>;

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

bool triangulate_general(const double* xyz, const Index* c, std::size_t n, const Eigen::Vector3d& normal,
                         std::vector<Index>& out) {
  // Project into the plane orthogonal to the normal, with (u, v, normal) right-handed so the
  // polygon's orientation is counter-clockwise in 2D.
  const Eigen::Vector3d w = normal.normalized();
  const Eigen::Vector3d u = w.unitOrthogonal();
  const Eigen::Vector3d v = w.cross(u);
  Cdt cdt;
  std::vector<Cdt::Vertex_handle> handles(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d q = point(xyz, c[i]);
    handles[i] = cdt.insert(Kernel::Point_2(q.dot(u), q.dot(v)));
    handles[i]->info() = c[i];
  }
  if (cdt.number_of_vertices() != n) return false;  // coincident corners in the plane
  for (std::size_t i = 0; i < n; ++i) {
    cdt.insert_constraint(handles[i], handles[(i + 1) % n]);
    // Constraints crossed (a vertex was added at the crossing): self-intersecting. Checked
    // after every edge, not once at the end, because the n edges of a star polygon cross
    // each other O(n^2) times (a 135 kB OBJ with one 4000-corner star face took 11 s, 1.3 GB).
    if (cdt.number_of_vertices() != n) return false;
  }

  // Flood from the infinite face; crossing a constrained edge increments the count.
  std::deque<Cdt::Face_handle> queue{cdt.infinite_face()};
  cdt.infinite_face()->info().crossings = 0;
  while (!queue.empty()) {
    const Cdt::Face_handle f = queue.front();
    queue.pop_front();
    for (int e = 0; e < 3; ++e) {
      const Cdt::Face_handle g = f->neighbor(e);
      if (g->info().crossings >= 0) continue;
      g->info().crossings = f->info().crossings + (f->is_constrained(e) ? 1 : 0);
      if (f->is_constrained(e)) queue.push_back(g);
      else queue.push_front(g);
    }
  }
  std::vector<Index> triangles;
  for (auto f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f) {
    if (f->info().crossings % 2 == 1) {
      triangles.insert(triangles.end(), {f->vertex(0)->info(), f->vertex(1)->info(), f->vertex(2)->info()});
    }
  }
  if (triangles.size() != 3 * (n - 2)) return false;  // not a simple polygon
  out.insert(out.end(), triangles.begin(), triangles.end());
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
