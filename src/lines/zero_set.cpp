// The zero set of a per-vertex scalar as chained polylines (zero_set.h).
#include "lines/zero_set.h"

#include "numerics/parallel.h"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <unordered_map>

namespace vertexflow::lines_detail {
namespace {

std::int64_t edge_key(Index a, Index b, Index n) {
  return static_cast<std::int64_t>(std::min(a, b)) * n + std::max(a, b);
}

// The face's segment: crossings of the aligned g on its edges, then clipped to keep >= 0.
FaceSegment face_segment(const Vertices& V, const Faces& F, const ZeroSetInput& in, Index f) {
  FaceSegment s;
  const Eigen::VectorXd& g = *in.g;
  const std::array<Index, 3> v{F(f, 0), F(f, 1), F(f, 2)};
  std::array<double, 2> keep{0, 0};
  int found = 0;
  for (int k = 0; k < 3; ++k) {
    const Index a = v[k], b = v[(k + 1) % 3];
    const double ga = g[a], gb = (in.align ? in.align(a, b) : 1.0) * g[b];
    if ((ga >= 0) == (gb >= 0)) continue;
    if (found == 2) return {};        // three crossings: the alignment turned around the face
    const double t = ga / (ga - gb);  // in (0, 1]: opposite signs
    s.end[found].edge = edge_key(a, b, V.rows());
    s.end[found].point = ((1 - t) * V.row(a) + t * V.row(b)).transpose();
    if (in.keep) keep[found] = (1 - t) * (*in.keep)[a] + t * (*in.keep)[b];
    ++found;
  }
  if (found != 2) return {};
  if (in.face_test) {
    const double g1 = (in.align ? in.align(v[0], v[1]) : 1.0) * g[v[1]];
    const double g2 = (in.align ? in.align(v[0], v[2]) : 1.0) * g[v[2]];
    if (!in.face_test(f, g[v[0]], g1, g2)) return {};
  }
  if (keep[0] < 0 && keep[1] < 0) return {};
  if (keep[0] < 0 || keep[1] < 0) {  // clip at the test's zero; that end is free
    const int out = keep[0] < 0 ? 0 : 1;
    const double t = keep[out] / (keep[out] - keep[1 - out]);
    s.end[out].point += t * (s.end[1 - out].point - s.end[out].point);
    s.end[out].edge = -1;
  }
  s.present = true;
  return s;
}

}  // namespace

void check_line_input(const Vertices& V, const Faces& F, std::initializer_list<Eigen::Index> per_vertex_rows,
                      const char* what) {
  for (const Eigen::Index rows : per_vertex_rows)
    if (rows != V.rows()) throw std::invalid_argument(std::string(what) + ": per-vertex data of another vertex count");
  if (F.rows() > 0 && (F.minCoeff() < 0 || F.maxCoeff() >= V.rows()))
    throw std::invalid_argument(std::string(what) + ": a face index is out of range");
}

std::vector<Polyline> zero_set(const Vertices& V, const Faces& F, const ZeroSetInput& input, LineType type) {
  const Index m = F.rows();
  std::vector<FaceSegment> segments(static_cast<std::size_t>(m));
  parallel_for_index(m, [&](Index f) { segments[static_cast<std::size_t>(f)] = face_segment(V, F, input, f); });
  // Crossing -> the faces through it (two on a manifold; more are chained in face order).
  std::unordered_map<std::int64_t, std::vector<Index>> faces_at;
  for (Index f = 0; f < m; ++f)
    for (const SegmentEnd& e : segments[static_cast<std::size_t>(f)].end)
      if (segments[static_cast<std::size_t>(f)].present && e.edge >= 0) faces_at[e.edge].push_back(f);
  std::vector<char> used(static_cast<std::size_t>(m), 0);
  // From face f, leaving through crossing `out`: the next unused face through it, or -1.
  auto next_face = [&](Index f, std::int64_t out) -> Index {
    if (out < 0) return -1;
    for (const Index g2 : faces_at[out])
      if (g2 != f && !used[static_cast<std::size_t>(g2)]) return g2;
    return -1;
  };
  // Walks from face f through crossing `at`, appending the far ends; returns the last crossing.
  auto walk = [&](Index f, std::int64_t at, std::int64_t stop, std::vector<Eigen::Vector3d>& out) {
    while (true) {
      const Index g2 = next_face(f, at);
      if (g2 < 0) return at;
      used[static_cast<std::size_t>(g2)] = 1;
      const FaceSegment& s = segments[static_cast<std::size_t>(g2)];
      const int far = s.end[0].edge == at ? 1 : 0;
      at = s.end[far].edge;
      f = g2;
      if (at >= 0 && at == stop) return at;
      out.push_back(s.end[far].point);
    }
  };
  std::vector<Polyline> lines;
  for (Index start = 0; start < m; ++start) {
    const FaceSegment& first = segments[static_cast<std::size_t>(start)];
    if (used[static_cast<std::size_t>(start)] || !first.present) continue;
    used[static_cast<std::size_t>(start)] = 1;
    // Forwards from end 1, then (if the chain did not close) backwards from end 0, and join.
    std::vector<Eigen::Vector3d> forward{first.end[0].point, first.end[1].point}, backward;
    const std::int64_t last = walk(start, first.end[1].edge, first.end[0].edge, forward);
    const bool closed = last >= 0 && last == first.end[0].edge;
    if (!closed) walk(start, first.end[0].edge, -1, backward);
    Polyline line;
    line.type = type;
    line.closed = closed;
    line.points.resize(static_cast<Index>(backward.size() + forward.size()), 3);
    Index row = 0;
    for (auto it = backward.rbegin(); it != backward.rend(); ++it) line.points.row(row++) = it->transpose();
    for (const auto& p : forward) line.points.row(row++) = p.transpose();
    lines.push_back(std::move(line));
  }
  return lines;
}

}  // namespace vertexflow::lines_detail
