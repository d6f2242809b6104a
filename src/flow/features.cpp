// Sharp features of a mesh (include/vertexflow/features.h).
#include "vertexflow/features.h"

#include "flow_setup.h"

#include "common/bucket_by_key.h"
#include "common/concurrent_union_find.h"
#include "numerics/parallel.h"

#include "vertexflow/curvature.h"

#include <algorithm>
#include <cmath>

namespace vertexflow {

SurfaceFeatures detect_features_without_normals(const Vertices& V, const Faces& F, const Topology& topology,
                                                double angle_degrees,
                                                const std::vector<std::array<Index, 2>>& crease_edges) {
  SurfaceFeatures features;
  const auto num_edges = static_cast<std::size_t>(topology.num_edges());
  features.sharp_edge.assign(num_edges, 0);
  // Given creases (seams): interior edges only, found in the sorted edge list.
  std::vector<char> given(crease_edges.empty() ? 0 : num_edges, 0);
  for (const auto& [a, b] : crease_edges) {
    const Index lo = std::min(a, b), hi = std::max(a, b);
    Index first = 0, last = topology.num_edges();
    while (first < last) {
      const Index mid = first + (last - first) / 2;
      if (topology.edges(mid, 0) < lo || (topology.edges(mid, 0) == lo && topology.edges(mid, 1) < hi))
        first = mid + 1;
      else
        last = mid;
    }
    if (first < topology.num_edges() && topology.edges(first, 0) == lo && topology.edges(first, 1) == hi &&
        topology.edge_face_count[static_cast<std::size_t>(first)] == 2)
      given[static_cast<std::size_t>(first)] = features.sharp_edge[static_cast<std::size_t>(first)] = 1;
  }
  const double cosine = std::cos(angle_degrees * M_PI / 180.0);
  if (angle_degrees < 180) {
    // Each interior edge from its lower face only (not boundary edges: g = -1), so the faces
    // can run in parallel: each edge's flag has one writer.
    parallel_for_index(static_cast<Index>(F.rows()), [&](Index f) {
      for (int k = 0; k < 3; ++k) {
        const Index g = topology.face_adjacency(f, k);
        if (g < f) continue;
        const Eigen::Vector3d nf = face_normal(V, F, f), ng = face_normal(V, F, g);
        const double product = nf.norm() * ng.norm();
        if (product > 0 && nf.dot(ng) < cosine * product)
          features.sharp_edge[static_cast<std::size_t>(topology.face_edges(f, k))] = 1;
      }
    });
  }
  features.on_sharp_edge.assign(static_cast<std::size_t>(topology.num_vertices), 0);
  for (std::size_t e = 0; e < num_edges; ++e) {
    if (!features.sharp_edge[e]) continue;
    for (int end = 0; end < 2; ++end)
      features.on_sharp_edge[static_cast<std::size_t>(topology.edges(static_cast<Index>(e), end))] = 1;
  }
  // A crease is a connected set of at least kMinCreaseEdges sharp edges. Shorter ones are the
  // noise of scans (a 40-degree threshold marks about 2% of bunny_uniform's vertices), where
  // holding vertices would only stop the flow.
  constexpr std::size_t kMinCreaseEdges = 3;
  {
    std::vector<Index> parent(static_cast<std::size_t>(topology.num_vertices));
    for (std::size_t v = 0; v < parent.size(); ++v) parent[v] = static_cast<Index>(v);
    auto root = [&](Index v) {
      while (parent[static_cast<std::size_t>(v)] != v)
        v = parent[static_cast<std::size_t>(v)] = parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(v)])];
      return v;
    };
    for (std::size_t e = 0; e < num_edges; ++e) {
      if (features.sharp_edge[e])
        parent[static_cast<std::size_t>(root(topology.edges(static_cast<Index>(e), 0)))] =
            root(topology.edges(static_cast<Index>(e), 1));
    }
    std::vector<std::size_t> edges_in(parent.size(), 0);
    for (std::size_t e = 0; e < num_edges; ++e) {
      if (features.sharp_edge[e]) ++edges_in[static_cast<std::size_t>(root(topology.edges(static_cast<Index>(e), 0)))];
    }
    for (std::size_t e = 0; e < num_edges; ++e) {
      if (features.sharp_edge[e] && (given.empty() || !given[e]) &&
          edges_in[static_cast<std::size_t>(root(topology.edges(static_cast<Index>(e), 0)))] < kMinCreaseEdges)
        features.sharp_edge[e] = 0;
    }
  }
  // Patches: the face sets connected across non-sharp interior edges, numbered in the order of
  // their first faces (as a flood fill from each unvisited face in order numbers them), on all
  // threads (concurrent_union_find.h; the flood fill took 0.43 s at 10M vertices).
  ConcurrentUnionFind patches(features.face_patch, static_cast<Index>(F.rows()));
  parallel_for_index(static_cast<Index>(F.rows()), [&](Index f) {
    for (int k = 0; k < 3; ++k) {
      const Index g = topology.face_adjacency(f, k);
      if (g > f && !features.sharp_edge[static_cast<std::size_t>(topology.face_edges(f, k))]) patches.unite(f, g);
    }
  });
  patches.number_sets();
  // A crease separates two patches: the features of a CAD part form a network that cuts the
  // surface into faces. A sharp edge with the same patch on both sides belongs to a chain that
  // ends inside one patch: on a scan, an under-sampled ridge or noise (bunny_uniform: 268 sharp
  // edges at 40 degrees, all but 24 of them such chains, whose 1- and 3-edge ends made 132
  // vertices corners), exactly where the flow should bring vertices, not freeze them. Unmarking
  // such an edge merges no patches (its sides are already one), so one pass finds them all.
  for (Index f = 0; f < F.rows(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const Index g = topology.face_adjacency(f, k);
      const auto e = static_cast<std::size_t>(topology.face_edges(f, k));
      if (g > f && (given.empty() || !given[e]) &&
          features.face_patch[static_cast<std::size_t>(f)] == features.face_patch[static_cast<std::size_t>(g)])
        features.sharp_edge[e] = 0;
    }
  }
  // Each vertex's sharp edges, by a counting sort over the edges in order: so each list is
  // increasing, which makes the projection's walks deterministic.
  const auto n = static_cast<std::size_t>(topology.num_vertices);
  KeyBuckets<Index, Index> sharp = bucket_by_key<Index, Index>(n, [&](auto&& emit) {
    for (std::size_t e = 0; e < num_edges; ++e)
      if (features.sharp_edge[e])
        for (int end = 0; end < 2; ++end)
          emit(static_cast<std::size_t>(topology.edges(static_cast<Index>(e), end)), static_cast<Index>(e));
  });
  features.sharp_start = std::move(sharp.start);
  features.sharp_at = std::move(sharp.items);
  features.vertex_kind.resize(n);
  for (std::size_t v = 0; v < n; ++v) {
    const auto count = static_cast<std::size_t>(features.sharp_count(static_cast<Index>(v)));
    features.vertex_kind[v] = count == 0   ? SurfaceFeatures::Kind::Smooth
                              : count == 2 ? SurfaceFeatures::Kind::Crease
                                           : SurfaceFeatures::Kind::Corner;
    // A crease that turns by more than the feature angle at v is a corner too: sliding v along
    // either edge would cut it off.
    if (count == 2) {
      Eigen::Vector3d direction[2];
      for (int k = 0; k < 2; ++k) {
        const Index e =
            features.sharp_at[static_cast<std::size_t>(features.sharp_start[v]) + static_cast<std::size_t>(k)];
        const Index other = topology.edges(e, 0) == static_cast<Index>(v) ? topology.edges(e, 1) : topology.edges(e, 0);
        direction[k] = (V.row(other) - V.row(static_cast<Index>(v))).transpose();
      }
      // Straight on: the two edges point in opposite directions (dot = -|a||b|).
      const double product = direction[0].norm() * direction[1].norm();
      if (!(product > 0) || -direction[0].dot(direction[1]) < cosine * product)
        features.vertex_kind[v] = SurfaceFeatures::Kind::Corner;
    }
  }
  return features;
}

SurfaceFeatures detect_features(const Vertices& V, const Faces& F, const Topology& topology, double angle_degrees,
                                const std::vector<std::array<Index, 2>>& crease_edges) {
  SurfaceFeatures features = detect_features_without_normals(V, F, topology, angle_degrees, crease_edges);
  features.vertex_normals = vertex_normals(V, F);
  return features;
}

}  // namespace vertexflow
