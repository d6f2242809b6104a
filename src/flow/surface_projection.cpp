// Closest points on the input surface by walks over its faces and sharp edges
// (surface_projection.h). The walks are ours because CGAL's AABB tree answers the global
// nearest-point question, the wrong one next to thin walls and creases.
#include "surface_projection.h"

#include "mesh/closest_point.h"
#include "vertexflow/curvature.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace vertexflow {
namespace {

struct Candidate {
  Index element = -1;  // face or edge
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  double squared_distance = std::numeric_limits<double>::infinity();
};

// Closest point of face f to x (mesh/closest_point.h); degenerate faces have no well-defined
// projection and are never candidates (infinite distance).
//
// A face whose bounding box is farther from x than the walk's best candidate so far cannot
// win (its closest point lies in its box, and a candidate must be strictly closer), so it is
// skipped before the region test, which costs several times the box's distance: most faces a
// walk offers are a ring or two away from a point that is almost on the surface. The skip
// changes no answer: the box's distance is a lower bound of the region test's up to rounding,
// a few ulps of the coordinates (kRoundingMargin covers 10^4 times that), so a skipped face's
// candidate would not have been strictly closer.
Candidate closest_on_face(const Eigen::Vector3d& x, const Vertices& V, const Faces& F, Index f, const Candidate& best) {
  constexpr double kRoundingMargin = 1e-10;
  Candidate c;
  const Eigen::Vector3d a = V.row(F(f, 0)), b = V.row(F(f, 1)), d = V.row(F(f, 2));
  if (best.squared_distance < std::numeric_limits<double>::infinity()) {
    const Eigen::Vector3d low = a.cwiseMin(b).cwiseMin(d), high = a.cwiseMax(b).cwiseMax(d);
    const Eigen::Vector3d gap = (low - x).cwiseMax(x - high).cwiseMax(0.0);
    const double scale = std::max({x.cwiseAbs().maxCoeff(), low.cwiseAbs().maxCoeff(), high.cwiseAbs().maxCoeff()});
    const double reach = std::sqrt(best.squared_distance) + kRoundingMargin * scale;
    if (gap.squaredNorm() > reach * reach) return c;
  }
  const TrianglePoint t = closest_point_on_triangle(x, a, b, d);
  if (!t.valid) return c;
  c.element = f;
  c.point = t.point;
  c.squared_distance = (c.point - x).squaredNorm();
  return c;
}

// Phong tessellation (Boubekeur and Alexa 2008, shape factor 3/4) of the point q of face f:
// q blended with its projections onto the tangent planes of the face's corners. It lifts a
// point of a flat facet onto a smooth surface through the vertices with their normals, so that
// vertices sliding over a curved region do not sink into the chords (spot lost 0.5% of its
// volume on the flat facets). Corners on sharp edges (SurfaceFeatures::on_sharp_edge)
// contribute q itself: no bulge across a crease.
Eigen::Vector3d phong_point(const Eigen::Vector3d& q, const Vertices& V, const Faces& F, Index f,
                            const Vertices& normals, const SurfaceFeatures& features) {
  const Eigen::Vector3d p[3] = {V.row(F(f, 0)), V.row(F(f, 1)), V.row(F(f, 2))};
  const Eigen::Vector3d n = (p[1] - p[0]).cross(p[2] - p[0]);
  const double area2 = n.squaredNorm();
  if (!(area2 > 0)) return q;
  Eigen::Vector3d lifted = Eigen::Vector3d::Zero(), direction = Eigen::Vector3d::Zero();
  for (int k = 0; k < 3; ++k) {
    // Barycentric coordinate of corner k: the sub-triangle opposite it over the whole.
    const double weight = (p[(k + 1) % 3] - q).cross(p[(k + 2) % 3] - q).dot(n) / area2;
    const Eigen::Vector3d nk = normals.row(F(f, k)).transpose();
    direction += weight * nk;
    Eigen::Vector3d on_plane = q;
    if (!features.on_sharp_edge[static_cast<std::size_t>(F(f, k))]) on_plane -= (q - p[k]).dot(nk) * nk;
    lifted += weight * on_plane;
  }
  constexpr double kShape = 0.75;
  // Only the height, along the interpolated vertex normal: Phong's tangential shift would undo
  // part of the flow. Both are continuous across edges, so a point on an edge gets the same
  // lift from either face (rounding decides which face the walk reports).
  const double length = direction.norm();
  const Eigen::Vector3d unit =
      length > 1e-12 ? Eigen::Vector3d(direction / length) : Eigen::Vector3d(n / std::sqrt(area2));
  return q + (kShape * (lifted - q).dot(unit)) * unit;
}

// Closest point of edge e to x: the projection onto the segment's line, clamped to the segment.
Candidate closest_on_edge(const Eigen::Vector3d& x, const Vertices& V, const Topology& topology, Index e) {
  Candidate c;
  const Eigen::Vector3d a = V.row(topology.edges(e, 0)), b = V.row(topology.edges(e, 1));
  const double length2 = (b - a).squaredNorm();
  if (!(length2 > 0)) return c;
  const double t = std::clamp((x - a).dot(b - a) / length2, 0.0, 1.0);
  c.element = e;
  c.point = a + t * (b - a);
  c.squared_distance = (c.point - x).squaredNorm();
  return c;
}

// Greedy descent: start from the candidates `first`, then repeatedly examine the neighbours of
// the best element, until none is closer. Each move strictly lowers the distance, so the walk
// ends; the step bound only guards against pathological inputs.
//
// The neighbourhoods of consecutive elements overlap (a face's neighbours are the faces of its
// three corners, so each face is offered 2-3 times per step and again by the next step), so
// the last kRecent elements evaluated are remembered and not evaluated again. The result is
// the same (an element's candidate does not change, and the first of equal candidates is kept);
// the point-triangle queries, most of the time of the density passes, fall by about half.
// evaluate(element, best) may skip an element that cannot be strictly closer than best (it
// returns an empty candidate): closest_on_face does.
template <class StartElements, class Neighbours, class Evaluate>
Candidate walk(StartElements&& first, Neighbours&& neighbours, Evaluate&& evaluate) {
  constexpr std::size_t kRecent = 64;
  std::array<Index, kRecent> recent;
  std::size_t evaluated = 0;
  Candidate best;
  auto consider = [&](Index element) {
    const std::size_t known = std::min(evaluated, kRecent);
    for (std::size_t k = 0; k < known; ++k)
      if (recent[k] == element) return;
    recent[evaluated++ % kRecent] = element;
    const Candidate c = evaluate(element, best);
    if (c.squared_distance < best.squared_distance) best = c;
  };
  first(consider);
  for (int step = 0; best.element >= 0 && step < 100000; ++step) {
    const Index current = best.element;
    neighbours(current, consider);
    if (best.element == current) break;
  }
  return best;
}

}  // namespace

void project_near_vertices(Vertices& points, const std::vector<Index>& rows, const Vertices& V, const Faces& F,
                           const Topology& topology, const SurfaceFeatures& features) {
  const Vertices& normals = features.vertex_normals;
  auto for_faces_of = [&](Index v, auto&& body) {
    const auto begin = topology.face_offsets[static_cast<std::size_t>(v)];
    const auto end = topology.face_offsets[static_cast<std::size_t>(v) + 1];
    for (Index i = begin; i < end; ++i) body(topology.vertex_faces[static_cast<std::size_t>(i)]);
  };
  auto project = [&](Index i) {
    const Eigen::Vector3d x = points.row(i).transpose();
    const auto kind = features.vertex_kind[static_cast<std::size_t>(i)];
    Candidate best;
    if (kind == SurfaceFeatures::Kind::Corner) {
      return;  // corners stay where they are (the flow fixes them too)
    } else if (kind == SurfaceFeatures::Kind::Crease) {
      auto sharp_edges_of = [&](Index v, auto&& body) { features.for_each_sharp_edge(v, body); };
      best = walk([&](auto&& consider) { sharp_edges_of(i, consider); },
                  [&](Index e, auto&& consider) {
                    sharp_edges_of(topology.edges(e, 0), consider);
                    sharp_edges_of(topology.edges(e, 1), consider);
                  },
                  [&](Index e, const Candidate&) { return closest_on_edge(x, V, topology, e); });
    } else {
      const auto begin = topology.face_offsets[static_cast<std::size_t>(i)];
      if (begin == topology.face_offsets[static_cast<std::size_t>(i) + 1]) return;
      const Index patch =
          features.face_patch[static_cast<std::size_t>(topology.vertex_faces[static_cast<std::size_t>(begin)])];
      auto in_patch = [&](auto&& consider) {
        return [&, consider](Index f) {
          if (features.face_patch[static_cast<std::size_t>(f)] == patch) consider(f);
        };
      };
      best = walk([&](auto&& consider) { for_faces_of(i, in_patch(consider)); },
                  [&](Index f, auto&& consider) {
                    for (int k = 0; k < 3; ++k) for_faces_of(F(f, k), in_patch(consider));
                  },
                  [&](Index f, const Candidate& so_far) { return closest_on_face(x, V, F, f, so_far); });
      if (best.element >= 0) best.point = phong_point(best.point, V, F, best.element, normals, features);
    }
    if (best.element >= 0) points.row(i) = best.point.transpose();
  };
  // Each row reads only its own query point and writes only itself: any order, same result.
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, rows.size(), 256),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t k = range.begin(); k != range.end(); ++k) project(rows[k]);
                    });
}

}  // namespace vertexflow
