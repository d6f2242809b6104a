#include "vertexflow/topology.h"

#include "common/bucket_by_key.h"
#include "common/concurrent_union_find.h"
#include "numerics/parallel.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <limits>
#include <memory>
#include <numeric>
#include <stdexcept>
#include <string>

namespace vertexflow {
namespace {

template <class Body>
void parallel_vertices(Index n, Body&& body) {
  tbb::parallel_for(tbb::blocked_range<Index>(0, n, 4096), [&](const tbb::blocked_range<Index>& r) {
    std::vector<Index> scratch;
    for (Index v = r.begin(); v != r.end(); ++v) body(v, scratch);
  });
}

// Sorts a vertex's list: by insertion for the usual dozen neighbours, where std::sort's set-up
// cost more than the sorting (bench_topology), and by std::sort for a fan's thousands.
void sort_small(std::vector<Index>& list) {
  constexpr std::size_t kInsertionUpTo = 32;
  if (list.size() > kInsertionUpTo) {
    std::sort(list.begin(), list.end());
    return;
  }
  for (std::size_t i = 1; i < list.size(); ++i) {
    const Index x = list[i];
    std::size_t j = i;
    for (; j > 0 && list[j - 1] > x; --j) list[j] = list[j - 1];
    list[j] = x;
  }
}

// The corner (0, 1 or 2) of face f at vertex v, which the face has.
int corner_of(const Faces& F, Index f, Index v) {
  return F(f, 0) == v ? 0 : F(f, 1) == v ? 1 : 2;
}

// Exclusive prefix sum of counts into offsets (size n + 1).
std::vector<Index> offsets_from_counts(const std::vector<Index>& counts) {
  std::vector<Index> offsets(counts.size() + 1, 0);
  std::inclusive_scan(counts.begin(), counts.end(), offsets.begin() + 1);
  return offsets;
}

// Fans of at most this many faces find a link vertex's wedges by scanning the fan's 2 count
// ends; larger ones (a cone apex can have thousands of faces) sort the ends once and search
// them. For the usual 4-8 faces the scan costs a third of the sort and its searches
// (bench_topology), which were the largest part of build_topology.
constexpr Index kSmallFan = 32;

// Chains the wedges of a vertex's fan (wedge w: face faces[w], spanning link vertices a[w] ->
// b[w]) into its ring, and reorders `faces` to match. degree(x): the number of wedges with link
// vertex x; other_wedge(x, w): the wedge at x other than w, or -1. `visited` holds count zeroed
// flags, `ordered` room for count faces. Returns false if the wedges are not one fan.
template <class Degree, class OtherWedge>
bool walk_fan(Index* faces, Index count, const Index* a, const Index* b, Index* ring, Index ring_size, Degree&& degree,
              OtherWedge&& other_wedge, char* visited, Index* ordered) {
  // Every link vertex in one or two wedges; each wedge end of degree 1 is a path end.
  Index ends = 0;
  for (Index w = 0; w < count; ++w)
    for (const Index x : {a[w], b[w]}) {
      const Index d = degree(x);
      if (d > 2) return false;
      ends += d == 1;
    }
  if (ends != 0 && ends != 2) return false;
  if ((ends == 0 ? count : count + 1) != ring_size) return false;
  // Start: on a path, at the end that is the 'a' of its wedge, so the walk follows the faces'
  // orientation when it is consistent (else at a 'b' end); on a cycle, at wedge 0.
  Index wedge = 0, current = a[0];
  if (ends == 2) {
    wedge = -1;
    for (Index w = 0; w < count && wedge < 0; ++w)
      if (degree(a[w]) == 1) wedge = w, current = a[w];
    for (Index w = 0; w < count && wedge < 0; ++w)
      if (degree(b[w]) == 1) wedge = w, current = b[w];
  }
  const Index start_vertex = current;
  Index filled = 0;
  ring[filled++] = current;
  for (Index step = 0; step < count; ++step) {
    if (visited[wedge]) return false;  // a wedge twice: more than one fan
    visited[wedge] = 1;
    ordered[step] = faces[wedge];
    current = current == a[wedge] ? b[wedge] : a[wedge];
    if (step + 1 < count || ends == 2) {
      if (filled >= ring_size) return false;
      ring[filled++] = current;
    }
    if (step + 1 < count) {
      wedge = other_wedge(current, wedge);
      if (wedge < 0) return false;  // the chain broke: more than one fan
    }
  }
  if (ends == 0 && current != start_vertex) return false;
  std::copy(ordered, ordered + count, faces);
  return filled == ring_size;
}

// Orders the one-ring of a vertex from its incident faces. Each incident face contributes a
// wedge (next corner, previous corner); at a manifold vertex the wedges chain into one path
// (boundary) or one cycle. Returns false if they do not (non-manifold vertex).
bool order_one_ring(Index v, const Faces& F, Index* faces, Index count, Index* ring, Index ring_size) {
  if (count < 1) return false;  // build_topology skips isolated vertices
  // Large fans' buffers are per thread: this runs once per vertex, so no allocation per call.
  thread_local std::vector<Index> large_ends, large_ordered;
  thread_local std::vector<char> large_visited;
  thread_local std::vector<std::pair<Index, Index>> incidence;
  Index small_ends[2 * kSmallFan], small_ordered[kSmallFan];
  char small_visited[kSmallFan] = {};
  const bool small = count <= kSmallFan;
  if (!small) {
    large_ends.resize(2 * static_cast<std::size_t>(count));
    large_ordered.resize(static_cast<std::size_t>(count));
    large_visited.assign(static_cast<std::size_t>(count), 0);
  }
  Index* a = small ? small_ends : large_ends.data();
  Index* b = a + count;
  for (Index w = 0; w < count; ++w) {
    const Index f = faces[w];
    const int c = corner_of(F, f, v);
    a[w] = F(f, (c + 1) % 3), b[w] = F(f, (c + 2) % 3);
  }
  if (small) {
    auto degree = [&](Index x) {
      Index d = 0;
      for (Index w = 0; w < count; ++w) d += (a[w] == x) + (b[w] == x);
      return d;
    };
    auto other_wedge = [&](Index x, Index wedge) {
      for (Index w = 0; w < count; ++w)
        if (w != wedge && (a[w] == x || b[w] == x)) return w;
      return Index{-1};
    };
    return walk_fan(faces, count, a, b, ring, ring_size, degree, other_wedge, small_visited, small_ordered);
  }
  // (link vertex, wedge), sorted by link vertex.
  incidence.resize(2 * static_cast<std::size_t>(count));
  for (Index w = 0; w < count; ++w)
    incidence[2 * static_cast<std::size_t>(w)] = {a[w], w}, incidence[2 * static_cast<std::size_t>(w) + 1] = {b[w], w};
  std::sort(incidence.begin(), incidence.end());
  auto first_at = [&](Index x) {
    return std::lower_bound(incidence.begin(), incidence.end(), std::pair{x, Index{-1}});
  };
  auto degree = [&](Index x) {
    Index d = 0;
    for (auto it = first_at(x); it != incidence.end() && it->first == x; ++it) ++d;
    return d;
  };
  auto other_wedge = [&](Index x, Index wedge) {
    for (auto it = first_at(x); it != incidence.end() && it->first == x; ++it)
      if (it->second != wedge) return it->second;
    return Index{-1};
  };
  return walk_fan(faces, count, a, b, ring, ring_size, degree, other_wedge, large_visited.data(), large_ordered.data());
}

}  // namespace

std::int64_t Topology::genus() const {
  if (!is_manifold() || !is_oriented) return -1;
  // Components that carry faces; isolated vertices are not surfaces.
  std::vector<char> has_face(static_cast<std::size_t>(num_components), 0);
  for (const Index c : face_component) has_face[static_cast<std::size_t>(c)] = 1;
  std::int64_t surfaces = std::count(has_face.begin(), has_face.end(), 1);
  std::int64_t isolated = 0;
  for (Index v = 0; v < num_vertices; ++v) isolated += face_offsets[v + 1] == face_offsets[v];
  const std::int64_t chi = euler_characteristic() - isolated;
  const std::int64_t twice = 2 * surfaces - static_cast<std::int64_t>(boundary_loops.size()) - chi;
  return twice >= 0 && twice % 2 == 0 ? twice / 2 : -1;
}

double mean_edge_length(const Vertices& V, const Topology& topology) {
  double sum = 0;
  for (Index e = 0; e < topology.num_edges(); ++e)
    sum += (V.row(topology.edges(e, 0)) - V.row(topology.edges(e, 1))).norm();
  return topology.num_edges() > 0 ? sum / topology.num_edges() : 0.0;
}

std::string describe_non_manifold(const Topology& topology) {
  std::string text = "the mesh is not manifold (" + std::to_string(topology.non_manifold_edges.size()) +
                     " non-manifold edges, " + std::to_string(topology.non_manifold_vertices.size()) +
                     " non-manifold vertices";
  if (!topology.non_manifold_vertices.empty())
    text += ", e.g. vertex " + std::to_string(topology.non_manifold_vertices.front());
  return text + ")";
}

Topology build_topology(const Faces& F, Index num_vertices) {
  Topology t;
  t.num_vertices = num_vertices;
  t.num_faces = static_cast<Index>(F.rows());
  const Index nv = num_vertices;
  const Index nf = t.num_faces;
  if (nf > 0 && (F.minCoeff() < 0 || F.maxCoeff() >= nv))
    throw std::invalid_argument("build_topology: a face index is outside [0, " + std::to_string(nv) + ")");
  if (static_cast<std::int64_t>(nf) * 3 > std::numeric_limits<Index>::max())
    throw std::invalid_argument("build_topology: more than (2^31 - 1) / 3 faces");
  for (Index f = 0; f < nf; ++f) {
    if (F(f, 0) == F(f, 1) || F(f, 1) == F(f, 2) || F(f, 2) == F(f, 0))
      throw std::invalid_argument("build_topology: face " + std::to_string(f) + " repeats a vertex");
  }

  // Vertex -> faces (counting sort, faces in increasing order per vertex), counted and placed
  // by two threads over the two halves of the faces: the same lists as one serial pass.
  {
    constexpr std::size_t kChunks = 2;
    KeyBuckets<Index, Index> faces =
        bucket_by_key_in_chunks<Index, Index>(static_cast<std::size_t>(nv), kChunks, [&](std::size_t c, auto&& emit) {
          const auto [first, last] = chunk_range(static_cast<std::size_t>(nf), kChunks, c);
          for (auto f = static_cast<Index>(first); f < static_cast<Index>(last); ++f)
            for (int k = 0; k < 3; ++k) emit(static_cast<std::size_t>(F(f, k)), f);
        });
    t.face_offsets = std::move(faces.start);
    t.vertex_faces = std::move(faces.items);
  }
  auto incident_faces = [&](Index v) {
    return std::pair{t.vertex_faces.data() + t.face_offsets[v], t.vertex_faces.data() + t.face_offsets[v + 1]};
  };

  // Undirected edges owned by their smaller vertex: neighbours w > v, sorted. Two passes
  // (count, then fill) so the edge list comes out sorted without a global sort.
  auto larger_neighbours = [&](Index v, std::vector<Index>& out) {
    out.clear();
    const auto [begin, end] = incident_faces(v);
    for (const Index* f = begin; f != end; ++f) {
      for (int k = 0; k < 3; ++k) {
        if (F(*f, k) > v) out.push_back(F(*f, k));
      }
    }
    sort_small(out);
    out.erase(std::unique(out.begin(), out.end()), out.end());
  };
  // Each vertex's list is computed once into a scratch area sized by its corner count (a
  // vertex with d incident faces has at most 2d neighbours), then compacted.
  // The scratch area is not initialised (a vector would zero it on one core first: half a GB at
  // 10M vertices); each vertex writes its part before it is read.
  std::vector<Index> edge_counts(static_cast<std::size_t>(nv));
  auto scratch_neighbours = std::make_unique_for_overwrite<Index[]>(2 * t.vertex_faces.size());
  parallel_vertices(nv, [&](Index v, std::vector<Index>& scratch) {
    larger_neighbours(v, scratch);
    std::copy(scratch.begin(), scratch.end(),
              scratch_neighbours.get() + 2 * static_cast<std::ptrdiff_t>(t.face_offsets[static_cast<std::size_t>(v)]));
    edge_counts[static_cast<std::size_t>(v)] = static_cast<Index>(scratch.size());
  });
  const std::vector<Index> edge_offsets = offsets_from_counts(edge_counts);
  const Index ne = edge_offsets.back();
  t.edges.resize(ne, 2);
  parallel_vertices(nv, [&](Index v, std::vector<Index>&) {
    const Index* source =
        scratch_neighbours.get() + 2 * static_cast<std::size_t>(t.face_offsets[static_cast<std::size_t>(v)]);
    Index e = edge_offsets[static_cast<std::size_t>(v)];
    for (Index i = 0; i < edge_counts[static_cast<std::size_t>(v)]; ++i, ++e)
      t.edges(e, 0) = v, t.edges(e, 1) = source[i];
  });
  scratch_neighbours.reset();
  // A vertex's edges are sorted by their other end: binary search, since one vertex can own
  // O(n) edges (a triangulated comb's spine, a fan), and a scan made the face loop quadratic.
  auto find_edge = [&](Index a, Index b) {
    if (a > b) std::swap(a, b);
    Index low = edge_offsets[static_cast<std::size_t>(a)], high = edge_offsets[static_cast<std::size_t>(a) + 1];
    while (low < high) {
      const Index middle = low + (high - low) / 2;
      if (t.edges.data()[2 * static_cast<std::size_t>(middle) + 1] < b)
        low = middle + 1;
      else
        high = middle;
    }
    return low;  // every face edge was recorded above, so this is it
  };

  // Face -> edges, edge -> faces and face -> faces in one pass over each edge's owner (its
  // smaller vertex): it meets each face edge it owns through its incident faces, which are in
  // face order here, so an edge's first two faces are in face order, and no other vertex writes
  // the owner's edges or their face slots.
  t.face_edges.resize(nf, 3);
  t.face_adjacency.resize(nf, 3);
  t.edge_face_count.assign(static_cast<std::size_t>(ne), 0);
  std::atomic<bool> oriented{true};
  parallel_vertices(nv, [&](Index a, std::vector<Index>& sides) {
    const Index first_edge = edge_offsets[static_cast<std::size_t>(a)];
    const Index owned = edge_offsets[static_cast<std::size_t>(a) + 1] - first_edge;
    sides.assign(2 * static_cast<std::size_t>(owned), -1);  // each edge's first two sides, 3 face + slot
    const auto [begin, end] = incident_faces(a);
    for (const Index* f = begin; f != end; ++f) {
      const int j = corner_of(F, *f, a);
      for (const int k : {(j + 1) % 3, (j + 2) % 3}) {
        if (F(*f, k) <= a) continue;
        // Slot j is the edge a -> F(f, j + 1); slot k = j + 2 the edge F(f, k) -> a.
        const int slot = k == (j + 1) % 3 ? j : k;
        const Index e = find_edge(a, F(*f, k));
        t.face_edges(*f, slot) = e;
        t.face_adjacency(*f, slot) = -1;
        const Index seen = t.edge_face_count[static_cast<std::size_t>(e)]++;
        if (seen < 2)
          sides[2 * static_cast<std::size_t>(e - first_edge) + static_cast<std::size_t>(seen)] = 3 * *f + slot;
      }
    }
    for (Index i = 0; i < owned; ++i) {
      if (t.edge_face_count[static_cast<std::size_t>(first_edge + i)] != 2) continue;
      const Index side0 = sides[2 * static_cast<std::size_t>(i)], side1 = sides[2 * static_cast<std::size_t>(i) + 1];
      const Index f0 = side0 / 3, f1 = side1 / 3;
      const int k0 = side0 % 3, k1 = side1 % 3;
      t.face_adjacency(f0, k0) = f1;
      t.face_adjacency(f1, k1) = f0;
      // Consistent orientation: the two faces run the shared edge opposite ways.
      if (F(f0, k0) == F(f1, k1)) oriented.store(false, std::memory_order_relaxed);
    }
  });
  t.is_oriented = oriented.load();

  // Each edge once, in order: the non-manifold edges, the boundary vertices, and the one-rings'
  // sizes (valence, the number of incident edges: a vertex's own edges, then one for each edge
  // it is the larger end of).
  std::vector<Index> valence = std::move(edge_counts);
  t.is_boundary_vertex.assign(static_cast<std::size_t>(nv), 0);
  bool has_boundary = false;
  for (Index e = 0; e < ne; ++e) {
    const Index count = t.edge_face_count[static_cast<std::size_t>(e)];
    const auto a = static_cast<std::size_t>(t.edges(e, 0)), b = static_cast<std::size_t>(t.edges(e, 1));
    ++valence[b];
    if (count > 2) t.non_manifold_edges.push_back(e);
    if (count == 1) t.is_boundary_vertex[a] = t.is_boundary_vertex[b] = 1, has_boundary = true;
  }
  t.ring_offsets = offsets_from_counts(valence);
  std::vector<Index>().swap(valence);
  t.ring_vertices.resize(static_cast<std::size_t>(t.ring_offsets.back()));
  t.is_manifold_vertex.assign(static_cast<std::size_t>(nv), 1);
  parallel_vertices(nv, [&](Index v, std::vector<Index>& scratch) {
    Index* ring = t.ring_vertices.data() + t.ring_offsets[static_cast<std::size_t>(v)];
    const Index ring_size =
        t.ring_offsets[static_cast<std::size_t>(v) + 1] - t.ring_offsets[static_cast<std::size_t>(v)];
    Index* faces = t.vertex_faces.data() + t.face_offsets[static_cast<std::size_t>(v)];
    const Index count = t.face_offsets[static_cast<std::size_t>(v) + 1] - t.face_offsets[static_cast<std::size_t>(v)];
    if (count == 0) return;  // isolated vertex: manifold in the trivial sense, empty ring
    if (order_one_ring(v, F, faces, count, ring, ring_size)) return;
    t.is_manifold_vertex[static_cast<std::size_t>(v)] = 0;
    std::sort(faces, faces + count);
    Index filled = 0;
    for (Index e = edge_offsets[static_cast<std::size_t>(v)]; e < edge_offsets[static_cast<std::size_t>(v) + 1]; ++e)
      ring[filled++] = t.edges(e, 1);
    // Smaller neighbours own the edge: scan incident faces for them.
    scratch.clear();
    for (Index i = 0; i < count; ++i) {
      for (int k = 0; k < 3; ++k) {
        if (F(faces[i], k) < v) scratch.push_back(F(faces[i], k));
      }
    }
    std::sort(scratch.begin(), scratch.end());
    scratch.erase(std::unique(scratch.begin(), scratch.end()), scratch.end());
    for (const Index w : scratch) ring[filled++] = w;
    std::sort(ring, ring + ring_size);
  });
  for (Index v = 0; v < nv; ++v) {
    if (!t.is_manifold_vertex[static_cast<std::size_t>(v)]) t.non_manifold_vertices.push_back(v);
  }

  // Boundary loops: walk boundary half-edges (face edges reversed) from vertex to vertex.
  if (has_boundary) {
    std::vector<Index> out_count(static_cast<std::size_t>(nv), 0);
    std::vector<std::pair<Index, Index>> half_edges;  // (from, to), reversed face order
    for (Index f = 0; f < nf; ++f) {
      for (int k = 0; k < 3; ++k) {
        if (t.edge_face_count[static_cast<std::size_t>(t.face_edges(f, k))] == 1)
          half_edges.emplace_back(F(f, (k + 1) % 3), F(f, k));
      }
    }
    std::sort(half_edges.begin(), half_edges.end());
    std::vector<char> used(half_edges.size(), 0);
    auto first_out = [&](Index from) {
      return std::lower_bound(half_edges.begin(), half_edges.end(), std::make_pair(from, Index{-1})) -
             half_edges.begin();
    };
    for (std::size_t h0 = 0; h0 < half_edges.size(); ++h0) {
      if (used[h0]) continue;
      std::vector<Index> loop;
      std::size_t h = h0;
      for (;;) {
        used[h] = 1;
        loop.push_back(half_edges[h].first);
        const Index to = half_edges[h].second;
        if (to == half_edges[h0].first) break;
        std::ptrdiff_t next = first_out(to);
        while (next < static_cast<std::ptrdiff_t>(half_edges.size()) &&
               half_edges[static_cast<std::size_t>(next)].first == to && used[static_cast<std::size_t>(next)])
          ++next;
        if (next >= static_cast<std::ptrdiff_t>(half_edges.size()) ||
            half_edges[static_cast<std::size_t>(next)].first != to)
          break;
        h = static_cast<std::size_t>(next);
      }
      t.boundary_loops.push_back(std::move(loop));
    }
  }

  // Connected components (vertices joined by faces), numbered in order of first vertex, on all
  // threads (concurrent_union_find.h).
  {
    ConcurrentUnionFind sets(t.vertex_component, nv);
    parallel_for_index(nf, [&](Index f) { sets.unite(F(f, 0), F(f, 1)), sets.unite(F(f, 1), F(f, 2)); });
    t.num_components = sets.number_sets();
    t.face_component.resize(static_cast<std::size_t>(nf));
    parallel_for_index(nf, [&](Index f) {
      t.face_component[static_cast<std::size_t>(f)] = t.vertex_component[static_cast<std::size_t>(F(f, 0))];
    });
  }
  return t;
}

}  // namespace vertexflow
