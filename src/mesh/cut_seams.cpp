// Seams stored cut open (mesh/cut_seams.h).
#include "mesh/cut_seams.h"

#include "mesh/fan_walk.h"
#include "mesh/position_key.h"

#include <cstdint>
#include <unordered_map>

namespace vertexflow {
namespace {

// Union-find whose root is the lowest index of its set.
Index root_of(std::vector<Index>& parent, Index v) {
  while (parent[static_cast<std::size_t>(v)] != v) {
    Index& p = parent[static_cast<std::size_t>(v)];
    p = parent[static_cast<std::size_t>(p)];
    v = p;
  }
  return v;
}

void unite(std::vector<Index>& parent, Index a, Index b) {
  a = root_of(parent, a);
  b = root_of(parent, b);
  if (a != b) parent[static_cast<std::size_t>(std::max(a, b))] = std::min(a, b);
}

struct SeamPair {
  Index a, b;  // one side's boundary half-edge a -> b
  Index c, d;  // the other side's c -> d, c at b's position and d at a's
};

}  // namespace

CutSeams find_cut_seams(const Vertices& V, const Faces& F, const Topology& topology) {
  CutSeams seams;
  const auto n = static_cast<std::size_t>(V.rows());
  bool open = false;
  for (std::size_t v = 0; v < n && !open; ++v) open = topology.is_boundary_vertex[v] != 0;
  if (!open) return seams;

  // Boundary vertices by position. (A copy may be two fans, as where a seam meets itself; the
  // check after welding judges the welded vertex.)
  std::vector<Index> position_of(n, -1);  // the lowest boundary vertex at the same position
  {
    std::unordered_map<PositionKey, Index, PositionKeyHash> first_at;
    for (std::size_t v = 0; v < n; ++v)
      if (topology.is_boundary_vertex[v])
        position_of[v] = first_at.try_emplace(position_key(V.data() + 3 * v), static_cast<Index>(v)).first->second;
  }

  // Boundary half-edges by the positions they join: a seam side is the only one from its start
  // position to its end position, and its twin the only one back. One end may be a single
  // vertex, where a seam ends inside the surface (a slit).
  struct Directed {
    Index count = 0;
    Index half_edge = -1;  // 3 f + k
  };
  std::unordered_map<std::uint64_t, Directed> directed;
  auto is_candidate_boundary = [&](Index f, int k) {
    return topology.edge_face_count[static_cast<std::size_t>(topology.face_edges(f, k))] == 1 &&
           position_of[static_cast<std::size_t>(F(f, k))] >= 0 &&
           position_of[static_cast<std::size_t>(F(f, (k + 1) % 3))] >= 0;
  };
  auto key_of = [&](Index from, Index to) {
    return half_edge_key(position_of[static_cast<std::size_t>(from)], position_of[static_cast<std::size_t>(to)]);
  };
  for (Index f = 0; f < topology.num_faces; ++f)
    for (int k = 0; k < 3; ++k)
      if (is_candidate_boundary(f, k)) {
        Directed& d = directed[key_of(F(f, k), F(f, (k + 1) % 3))];
        if (d.count++ == 0) d.half_edge = 3 * f + k;
      }
  std::vector<SeamPair> pairs;
  for (Index f = 0; f < topology.num_faces; ++f)
    for (int k = 0; k < 3; ++k) {
      if (!is_candidate_boundary(f, k)) continue;
      const Index a = F(f, k), b = F(f, (k + 1) % 3);
      if (position_of[static_cast<std::size_t>(a)] == position_of[static_cast<std::size_t>(b)]) continue;
      const auto twin = directed.find(key_of(b, a));
      if (twin == directed.end() || twin->second.count != 1 || directed[key_of(a, b)].count != 1) continue;
      const Index h = twin->second.half_edge;
      if (h < 3 * f + k) continue;  // recorded from the twin's face
      pairs.push_back({a, b, F(h / 3, h % 3), F(h / 3, (h % 3 + 1) % 3)});
    }
  if (pairs.empty()) return seams;

  // Weld, then take apart every welded vertex that is not a single fan, until none is left.
  std::vector<Index> parent(n);
  for (std::size_t v = 0; v < n; ++v) parent[v] = static_cast<Index>(v);
  for (const SeamPair& p : pairs) {
    unite(parent, p.a, p.d);
    unite(parent, p.b, p.c);
  }
  for (int round = 0;; ++round) {
    std::vector<Index> root(n), members(n, 0);
    for (std::size_t v = 0; v < n; ++v)
      ++members[static_cast<std::size_t>(root[v] = root_of(parent, static_cast<Index>(v)))];
    Faces welded(F.rows(), 3);
    for (Eigen::Index f = 0; f < F.rows(); ++f)
      for (int k = 0; k < 3; ++k) welded(f, k) = root[static_cast<std::size_t>(F(f, k))];
    const Topology t = build_topology(welded, static_cast<Index>(n));
    std::vector<char> take_apart(n, 0);  // welded vertices (roots) that are not a single fan
    bool any = false;
    auto mark = [&](Index r) {
      if (members[static_cast<std::size_t>(r)] < 2) return;
      take_apart[static_cast<std::size_t>(r)] = 1;
      any = true;
    };
    for (const Index v : t.non_manifold_vertices) mark(v);
    for (const Index e : t.non_manifold_edges) {
      mark(t.edges(e, 0));
      mark(t.edges(e, 1));
    }
    if (!any) break;
    for (std::size_t v = 0; v < n; ++v)
      if (take_apart[static_cast<std::size_t>(root[v])]) parent[v] = static_cast<Index>(v);
    if (round == 8) return seams;  // never seen: weld nothing rather than loop on
  }

  seams.representative.resize(n);
  for (std::size_t v = 0; v < n; ++v) {
    seams.representative[v] = root_of(parent, static_cast<Index>(v));
    if (seams.representative[v] != static_cast<Index>(v)) ++seams.vertices_welded;
  }
  const auto& rep = seams.representative;
  for (const SeamPair& p : pairs) {
    const Index a = rep[static_cast<std::size_t>(p.a)], b = rep[static_cast<std::size_t>(p.b)];
    if (a == rep[static_cast<std::size_t>(p.d)] && b == rep[static_cast<std::size_t>(p.c)])
      seams.edges.push_back({std::min(a, b), std::max(a, b)});
  }
  if (seams.vertices_welded == 0) seams.representative.clear();
  return seams;
}

}  // namespace vertexflow
