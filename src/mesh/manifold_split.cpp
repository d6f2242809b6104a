#include "vertexflow/manifold_split.h"

#include <algorithm>
#include <numeric>
#include <stdexcept>

namespace vertexflow {
namespace {

// The vertex face f's edge k starts from, with the face reversed or not: reversing swaps
// corners 1 and 2, which turns every edge of the face around.
Index edge_start(const Faces& F, Index f, int k, bool reversed) {
  return reversed ? F(f, (k + 1) % 3) : F(f, k);
}

// The corner index k of face g whose edge is e.
int edge_slot(const Topology& topology, Index g, Index e) {
  for (int k = 0; k < 3; ++k)
    if (topology.face_edges(g, k) == e) return k;
  return -1;
}

Index find(std::vector<Index>& parent, Index i) {
  while (parent[static_cast<std::size_t>(i)] != i) {
    parent[static_cast<std::size_t>(i)] = parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(i)])];
    i = parent[static_cast<std::size_t>(i)];
  }
  return i;
}

}  // namespace

ManifoldSplit split_non_manifold(const Vertices& V, const Faces& F, const Topology& topology) {
  const Index nv = static_cast<Index>(V.rows()), nf = static_cast<Index>(F.rows());
  if (topology.num_vertices != nv || topology.num_faces != nf)
    throw std::invalid_argument("split_non_manifold: the topology was built for another mesh");
  const Index ne = topology.num_edges();
  ManifoldSplit split;

  // Edges crossed by the walks: exactly two faces, and no orientation conflict.
  std::vector<char> cut(static_cast<std::size_t>(ne), 0);
  for (Index e = 0; e < ne; ++e) {
    const Index count = topology.edge_face_count[static_cast<std::size_t>(e)];
    cut[static_cast<std::size_t>(e)] = count != 2 ? 1 : 0;
    split.cut_non_manifold_edges += count > 2 ? 1 : 0;
  }

  // Orientation: breadth-first over each component from its lowest face.
  split.reversed_face.assign(static_cast<std::size_t>(nf), 0);
  std::vector<char> visited(static_cast<std::size_t>(nf), 0);
  std::vector<Index> queue;
  for (Index seed = 0; seed < nf; ++seed) {
    if (visited[static_cast<std::size_t>(seed)]) continue;
    queue.assign(1, seed);
    visited[static_cast<std::size_t>(seed)] = 1;
    for (std::size_t head = 0; head < queue.size(); ++head) {
      const Index f = queue[head];
      const bool f_reversed = split.reversed_face[static_cast<std::size_t>(f)];
      for (int k = 0; k < 3; ++k) {
        const Index e = topology.face_edges(f, k);
        if (cut[static_cast<std::size_t>(e)]) continue;
        const Index g = topology.face_adjacency(f, k);
        const int slot = edge_slot(topology, g, e);
        const Index from_f = edge_start(F, f, k, f_reversed);
        // Consistent when the two faces run along the edge in opposite directions.
        const bool g_reversed = F(g, slot) == from_f;
        if (!visited[static_cast<std::size_t>(g)]) {
          visited[static_cast<std::size_t>(g)] = 1;
          split.reversed_face[static_cast<std::size_t>(g)] = g_reversed ? 1 : 0;
          queue.push_back(g);
        } else if (static_cast<bool>(split.reversed_face[static_cast<std::size_t>(g)]) != g_reversed) {
          cut[static_cast<std::size_t>(e)] = 1;
          ++split.cut_orientation_edges;
        }
      }
    }
    // Keep the orientation most of the component's faces had.
    const auto reversed = std::count_if(queue.begin(), queue.end(),
                                        [&](Index f) { return split.reversed_face[static_cast<std::size_t>(f)]; });
    if (2 * static_cast<std::size_t>(reversed) > queue.size())
      for (const Index f : queue) split.reversed_face[static_cast<std::size_t>(f)] ^= 1;
  }
  split.reversed_faces = static_cast<Index>(std::count(split.reversed_face.begin(), split.reversed_face.end(), 1));

  // Fans: the faces around each vertex joined across uncut edges that contain the vertex.
  // fan_of[c] for corner c = 3 f + k is the fan's representative face.
  std::vector<Index> parent(static_cast<std::size_t>(nf));
  std::iota(parent.begin(), parent.end(), Index{0});
  std::vector<Index> corner_copy(static_cast<std::size_t>(3 * nf), -1);
  split.first_copy.assign(static_cast<std::size_t>(nv) + 1, 0);
  split.held.assign(static_cast<std::size_t>(nv), 0);
  std::vector<Index> fan_roots;
  Index copies = 0;
  for (Index v = 0; v < nv; ++v) {
    split.first_copy[static_cast<std::size_t>(v)] = copies;
    const Index begin = topology.face_offsets[static_cast<std::size_t>(v)];
    const Index end = topology.face_offsets[static_cast<std::size_t>(v) + 1];
    for (Index i = begin; i < end; ++i) {
      const Index f = topology.vertex_faces[static_cast<std::size_t>(i)];
      parent[static_cast<std::size_t>(f)] = f;
    }
    for (Index i = begin; i < end; ++i) {
      const Index f = topology.vertex_faces[static_cast<std::size_t>(i)];
      for (int k = 0; k < 3; ++k) {
        // The two edges of f at v: the one starting at v's corner and the one ending there.
        if (F(f, k) != v && F(f, (k + 1) % 3) != v) continue;
        const Index e = topology.face_edges(f, k);
        if (cut[static_cast<std::size_t>(e)]) continue;
        const Index a = find(parent, f), b = find(parent, topology.face_adjacency(f, k));
        if (a != b) parent[static_cast<std::size_t>(std::max(a, b))] = std::min(a, b);
      }
    }
    // One copy per fan, fans in the order of their lowest face.
    fan_roots.clear();
    for (Index i = begin; i < end; ++i)
      fan_roots.push_back(find(parent, topology.vertex_faces[static_cast<std::size_t>(i)]));
    std::sort(fan_roots.begin(), fan_roots.end());
    fan_roots.erase(std::unique(fan_roots.begin(), fan_roots.end()), fan_roots.end());
    for (Index i = begin; i < end; ++i) {
      const Index f = topology.vertex_faces[static_cast<std::size_t>(i)];
      const Index fan =
          static_cast<Index>(std::lower_bound(fan_roots.begin(), fan_roots.end(), find(parent, f)) - fan_roots.begin());
      for (int k = 0; k < 3; ++k)
        if (F(f, k) == v) corner_copy[static_cast<std::size_t>(3 * f + k)] = copies + fan;
    }
    const Index fans = std::max<Index>(1, static_cast<Index>(fan_roots.size()));
    split.held[static_cast<std::size_t>(v)] = fans > 1 ? 1 : 0;
    split.held_vertices += fans > 1 ? 1 : 0;
    copies += fans;
  }
  split.first_copy[static_cast<std::size_t>(nv)] = copies;

  split.V.resize(copies, 3);
  split.source_vertex.resize(static_cast<std::size_t>(copies));
  for (Index v = 0; v < nv; ++v) {
    for (Index s = split.first_copy[static_cast<std::size_t>(v)]; s < split.first_copy[static_cast<std::size_t>(v) + 1];
         ++s) {
      split.V.row(s) = V.row(v);
      split.source_vertex[static_cast<std::size_t>(s)] = v;
    }
  }
  split.F.resize(nf, 3);
  for (Index f = 0; f < nf; ++f) {
    for (int k = 0; k < 3; ++k) split.F(f, k) = corner_copy[static_cast<std::size_t>(3 * f + k)];
    if (split.reversed_face[static_cast<std::size_t>(f)]) std::swap(split.F(f, 1), split.F(f, 2));
  }
  return split;
}

}  // namespace vertexflow
