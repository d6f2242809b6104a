// Occluding contours (lines.h): per-face zero crossings of n . (eye - p), chained across faces.
#include "numerics/parallel.h"
#include "vertexflow/lines.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <stdexcept>
#include <unordered_map>
#include <vector>

namespace vertexflow {
namespace {

// One face's piece of the zero set: the crossings on two of its edges, each edge by its sorted
// vertex pair.
struct Segment {
  std::array<std::int64_t, 2> edge{-1, -1};
  std::array<Eigen::Vector3d, 2> point;
};

std::int64_t edge_key(Index a, Index b, Index n) {
  return static_cast<std::int64_t>(std::min(a, b)) * n + std::max(a, b);
}

}  // namespace

std::vector<Polyline> occluding_contours(const Vertices& V, const Faces& F, const Vertices& normals, const View& view) {
  const Index n = V.rows(), m = F.rows();
  if (normals.rows() != n) throw std::invalid_argument("occluding contours: one normal per vertex is needed");
  if (m > 0 && (F.minCoeff() < 0 || F.maxCoeff() >= n))
    throw std::invalid_argument("occluding contours: a face index is out of range");
  // g per vertex; 0 counts as front-facing.
  Eigen::VectorXd g(n);
  parallel_for_index(n, [&](Index v) {
    const Eigen::Vector3d normal = normals.row(v).transpose();
    g[v] = view.orthographic ? -normal.dot(view.direction) : normal.dot(view.eye - V.row(v).transpose());
  });
  std::vector<Segment> segments(static_cast<std::size_t>(m));
  parallel_for_index(m, [&](Index f) {
    Segment& s = segments[static_cast<std::size_t>(f)];
    int found = 0;
    for (int k = 0; k < 3 && found < 2; ++k) {
      const Index a = F(f, k), b = F(f, (k + 1) % 3);
      const bool front_a = g[a] >= 0, front_b = g[b] >= 0;
      if (front_a == front_b) continue;
      const double t = g[a] / (g[a] - g[b]);  // in (0, 1]: g[a] and g[b] have opposite signs
      s.edge[found] = edge_key(a, b, n);
      s.point[found] = ((1 - t) * V.row(a) + t * V.row(b)).transpose();
      ++found;
    }
    if (found != 2) s.edge = {-1, -1};  // no crossing (a face has 0 or 2)
  });
  // Crossing -> the (up to two on a manifold; more are chained in face order) faces through it.
  std::unordered_map<std::int64_t, std::vector<Index>> faces_at;
  for (Index f = 0; f < m; ++f)
    for (const std::int64_t e : segments[static_cast<std::size_t>(f)].edge)
      if (e >= 0) faces_at[e].push_back(f);
  std::vector<char> used(static_cast<std::size_t>(m), 0);
  std::vector<Polyline> lines;
  // From face f, leaving through its crossing `out`: the next unused face through `out`.
  auto next_face = [&](Index f, std::int64_t out) -> Index {
    for (const Index g2 : faces_at[out])
      if (g2 != f && !used[static_cast<std::size_t>(g2)]) return g2;
    return -1;
  };
  auto other_end = [&](Index f, std::int64_t in) {
    const Segment& s = segments[static_cast<std::size_t>(f)];
    return s.edge[0] == in ? 1 : 0;
  };
  for (Index start = 0; start < m; ++start) {
    if (used[static_cast<std::size_t>(start)] || segments[static_cast<std::size_t>(start)].edge[0] < 0) continue;
    used[static_cast<std::size_t>(start)] = 1;
    const Segment& first = segments[static_cast<std::size_t>(start)];
    // Walk forwards from crossing 1, then backwards from crossing 0, and join.
    std::vector<Eigen::Vector3d> forward{first.point[0], first.point[1]};
    std::int64_t at = first.edge[1];
    Index f = start;
    bool closed = false;
    while (true) {
      const Index g2 = next_face(f, at);
      if (g2 < 0) {
        closed = at == first.edge[0] && faces_at[at].size() >= 2;
        break;
      }
      used[static_cast<std::size_t>(g2)] = 1;
      const int end = other_end(g2, at);
      const Segment& s = segments[static_cast<std::size_t>(g2)];
      at = s.edge[end];
      f = g2;
      if (at == first.edge[0]) {
        closed = true;
        break;
      }
      forward.push_back(s.point[end]);
    }
    std::vector<Eigen::Vector3d> backward;
    if (!closed) {
      at = first.edge[0];
      f = start;
      while (true) {
        const Index g2 = next_face(f, at);
        if (g2 < 0) break;
        used[static_cast<std::size_t>(g2)] = 1;
        const int end = other_end(g2, at);
        const Segment& s = segments[static_cast<std::size_t>(g2)];
        at = s.edge[end];
        f = g2;
        backward.push_back(s.point[end]);
      }
    }
    Polyline line;
    line.closed = closed;
    line.points.resize(static_cast<Index>(backward.size() + forward.size()), 3);
    Index row = 0;
    for (auto it = backward.rbegin(); it != backward.rend(); ++it) line.points.row(row++) = it->transpose();
    for (const auto& p : forward) line.points.row(row++) = p.transpose();
    lines.push_back(std::move(line));
  }
  return lines;
}

}  // namespace vertexflow
