// Triangulation of large and awkward polygons, read as one OBJ face through read_mesh_from_memory:
// the result must cover the polygon exactly (n - 2 triangles facing its normal, none outside
// it, areas adding up to the polygon's) and be constrained Delaunay; polygons that cross
// themselves are still fanned and reported.
#include "vertexflow/io.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <sstream>
#include <string>
#include <vector>

namespace vertexflow {
namespace {

struct Point {
  double x, y;
};
using Polygon = std::vector<Point>;

// A plane in space: corner (x, y) of a polygon sits at origin + x * e1 + y * e2.
struct Frame {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::Vector3d e1 = Eigen::Vector3d::UnitX();
  Eigen::Vector3d e2 = Eigen::Vector3d::UnitY();
  [[nodiscard]] Eigen::Vector3d place(const Point& p) const { return origin + p.x * e1 + p.y * e2; }
  [[nodiscard]] Point project(const Eigen::Vector3d& q) const { return {(q - origin).dot(e1), (q - origin).dot(e2)}; }
};

// A counter-clockwise comb: a spine along y in [0, 1] and n / 4 teeth of width 1, gaps of
// width 1, reaching up to y = n / 4 and leaning sideways by n / 16, so that each long edge
// passes O(n) corners closely (the shape that made the old triangulation quadratic).
Polygon comb(int n) {
  const int teeth = n / 4;
  const double height = teeth, lean = n / 16.0;
  Polygon polygon = {{0, 0}, {2.0 * teeth - 1, 0}};
  for (int k = teeth - 1; k >= 0; --k) {
    polygon.push_back({2.0 * k + 1 + lean, height});
    polygon.push_back({2.0 * k + lean, height});
    if (k > 0) {
      polygon.push_back({2.0 * k, 1});
      polygon.push_back({2.0 * k - 1, 1});
    }
  }
  return polygon;
}

// A counter-clockwise strip wound `turns` times around the origin: out along an Archimedean
// spiral, back along a parallel one inside it.
Polygon spiral(int corners_per_arm, double turns) {
  Polygon polygon;
  const double pi = 3.14159265358979323846;
  auto arm = [&](int i, double offset) {
    const double angle = 2 * pi * turns * i / (corners_per_arm - 1);
    const double radius = 1 + angle / pi + offset;
    return Point{radius * std::cos(angle), radius * std::sin(angle)};
  };
  for (int i = 0; i < corners_per_arm; ++i) polygon.push_back(arm(i, 1.2));
  for (int i = corners_per_arm - 1; i >= 0; --i) polygon.push_back(arm(i, 0.0));
  return polygon;
}

std::string obj_of(const Polygon& polygon, const Frame& frame) {
  std::ostringstream obj;
  obj.precision(17);
  for (const Point& p : polygon) {
    const Eigen::Vector3d q = frame.place(p);
    obj << "v " << q.x() << ' ' << q.y() << ' ' << q.z() << '\n';
  }
  obj << 'f';
  for (std::size_t i = 0; i < polygon.size(); ++i) obj << ' ' << i + 1;
  obj << '\n';
  return obj.str();
}

double shoelace_area(const Polygon& polygon) {
  double twice = 0;
  for (std::size_t i = 0; i < polygon.size(); ++i) {
    const Point &a = polygon[i], &b = polygon[(i + 1) % polygon.size()];
    twice += a.x * b.y - b.x * a.y;
  }
  return twice / 2;
}

// Crossing-number test; the centroids checked here are never on the boundary.
bool inside(const Polygon& polygon, const Point& p) {
  bool in = false;
  for (std::size_t i = 0, j = polygon.size() - 1; i < polygon.size(); j = i++) {
    const Point &a = polygon[i], &b = polygon[j];
    if ((a.y > p.y) != (b.y > p.y) && p.x < a.x + (p.y - a.y) * (b.x - a.x) / (b.y - a.y)) in = !in;
  }
  return in;
}

// Reads `polygon` (counter-clockwise in `frame`) as one OBJ face and checks that its triangles
// tile it: n - 2 of them, each facing the polygon's normal with its centroid inside, their
// areas adding up to the polygon's.
Mesh expect_exact_triangulation(const Polygon& polygon, const Frame& frame = {}) {
  ReadReport report;
  const Mesh mesh = read_mesh_from_memory(obj_of(polygon, frame), MeshFormat::Obj, "polygon.obj", &report);
  EXPECT_EQ(report.polygons_triangulated, 1);
  EXPECT_EQ(report.polygons_fanned, 0);
  EXPECT_EQ(report.zero_area_faces_removed, 0);
  EXPECT_EQ(mesh.num_faces(), static_cast<Index>(polygon.size()) - 2);
  const Eigen::Vector3d normal = frame.e1.cross(frame.e2).normalized();
  double area = 0;
  int facing_away = 0, outside = 0;
  for (Index f = 0; f < mesh.num_faces(); ++f) {
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)), c = mesh.V.row(mesh.F(f, 2));
    const double signed_area = 0.5 * (b - a).cross(c - a).dot(normal);
    area += signed_area;
    if (!(signed_area > 0)) ++facing_away;
    if (!inside(polygon, frame.project((a + b + c) / 3))) ++outside;
  }
  EXPECT_EQ(facing_away, 0);
  EXPECT_EQ(outside, 0);
  const double expected = shoelace_area(polygon);
  EXPECT_NEAR(area, expected, 1e-9 * expected);
  return mesh;
}

// Constrained Delaunay, checked on a convex polygon (where it is plain Delaunay): no corner lies
// inside a triangle's circumcircle (up to rounding, for corners on it).
void expect_delaunay(const Mesh& mesh, const Frame& frame = {}) {
  int violations = 0;
  for (Index f = 0; f < mesh.num_faces(); ++f) {
    const Point a = frame.project(mesh.V.row(mesh.F(f, 0))), b = frame.project(mesh.V.row(mesh.F(f, 1))),
                c = frame.project(mesh.V.row(mesh.F(f, 2)));
    const double d = 2 * (a.x * (b.y - c.y) + b.x * (c.y - a.y) + c.x * (a.y - b.y));
    const double a2 = a.x * a.x + a.y * a.y, b2 = b.x * b.x + b.y * b.y, c2 = c.x * c.x + c.y * c.y;
    const Point center{(a2 * (b.y - c.y) + b2 * (c.y - a.y) + c2 * (a.y - b.y)) / d,
                       (a2 * (c.x - b.x) + b2 * (a.x - c.x) + c2 * (b.x - a.x)) / d};
    const double radius = std::hypot(a.x - center.x, a.y - center.y);
    for (Index v = 0; v < mesh.num_vertices(); ++v) {
      const Point p = frame.project(mesh.V.row(v));
      if (std::hypot(p.x - center.x, p.y - center.y) < radius * (1 - 1e-9)) ++violations;
    }
  }
  EXPECT_EQ(violations, 0);
}

TEST(TriangulatePolygon, CombWithLeaningTeeth) {
  expect_exact_triangulation(comb(4000));
}

TEST(TriangulatePolygon, Spiral) {
  expect_exact_triangulation(spiral(400, 3.5));
}

TEST(TriangulatePolygon, TiltedPlane) {
  Frame frame;
  frame.origin = {3, -2, 7};
  frame.e1 = Eigen::Vector3d(1, 2, 3).unitOrthogonal();
  frame.e2 = Eigen::Vector3d(1, 2, 3).normalized().cross(frame.e1);
  expect_exact_triangulation(spiral(150, 2.25), frame);
  expect_exact_triangulation(comb(400), frame);
}

TEST(TriangulatePolygon, ClockwiseInTheXyPlane) {
  // The comb mirrored in the x axis runs clockwise: its normal is -z, and so is the triangles'.
  Frame frame;
  frame.e2 = -Eigen::Vector3d::UnitY();
  expect_exact_triangulation(comb(400), frame);
}

TEST(TriangulatePolygon, StraightCornersOnTheEdges) {
  // Corners on the line of their neighbours, as where coplanar faces were merged; horizontal
  // runs of them are what CGAL's monotone partition mishandles (CGAL issue 3332), so they are
  // left out of it and put back.
  const Polygon merged = {{3, -2}, {3, -1}, {3, 2},  {1, 2},  {1, 3},  {1, 4},  {0, 4},
                          {0, 3},  {0, 2},  {-1, 2}, {-2, 2}, {-2, 0}, {-3, 0}, {-3, -2}};
  expect_exact_triangulation(merged);
  // A plus sign with every lattice point of its outline as a corner.
  Polygon plus;
  const int outline[][2] = {{1, -3}, {1, -1}, {3, -1}, {3, 1},   {1, 1},   {1, 3},
                            {-1, 3}, {-1, 1}, {-3, 1}, {-3, -1}, {-1, -1}, {-1, -3}};
  for (int i = 0; i < 12; ++i) {
    const int* from = outline[i];
    const int* to = outline[(i + 1) % 12];
    const int steps = std::abs(to[0] - from[0]) + std::abs(to[1] - from[1]);
    for (int s = 0; s < steps; ++s)
      plus.push_back({from[0] + (to[0] - from[0]) * s / static_cast<double>(steps),
                      from[1] + (to[1] - from[1]) * s / static_cast<double>(steps)});
  }
  expect_exact_triangulation(plus);
}

TEST(TriangulatePolygon, ConvexPolygonIsDelaunay) {
  // Corners on an ellipse: a fan or a zigzag would give needles, Delaunay does not.
  Polygon ellipse;
  for (int i = 0; i < 96; ++i) {
    const double angle = 2 * 3.14159265358979323846 * i / 96;
    ellipse.push_back({5 * std::cos(angle), std::sin(angle)});
  }
  expect_delaunay(expect_exact_triangulation(ellipse));
}

TEST(TriangulatePolygon, SelfIntersectingBowTieIsFanned) {
  // Edges 2-3 and 4-5 cross.
  const std::string obj = "v 0 0 0\nv 2 0.5 0\nv 4 3 0\nv 4 0 0\nv 2 2.5 0\nv 0 3 0\nf 1 2 3 4 5 6\n";
  ReadReport report;
  const Mesh mesh = read_mesh_from_memory(obj, MeshFormat::Obj, "bow-tie.obj", &report);
  EXPECT_EQ(report.polygons_triangulated, 1);
  EXPECT_EQ(report.polygons_fanned, 1);
  EXPECT_EQ(mesh.num_faces(), 4);
}

}  // namespace
}  // namespace vertexflow
