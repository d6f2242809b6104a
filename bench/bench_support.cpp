#include "bench_support.h"

#include "vertexflow/io.h"

#include <limits>
#include <ostream>
#include <stdexcept>
#include <string>
#include <vector>

#ifndef VERTEXFLOW_DATA_DIR
#error "VERTEXFLOW_DATA_DIR must be defined (bench/CMakeLists.txt sets it)"
#endif

namespace vertexflow::bench {

std::filesystem::path data_dir() { return VERTEXFLOW_DATA_DIR; }

Mesh subdivide_uniform(const Mesh& mesh, int segments) {
  if (segments < 1) throw std::invalid_argument("subdivide_uniform: segments must be at least 1");
  const Index n = segments;
  const Index nv0 = mesh.num_vertices();
  const Index nf0 = mesh.num_faces();
  // The edge list and face -> edge map give every undirected edge one index, so both faces
  // of an edge find the same points on it.
  const Topology topology = build_topology(mesh.F, nv0);
  const Index ne0 = topology.num_edges();
  const Index per_edge = n - 1;
  const Index per_face = (n - 1) * (n - 2) / 2;
  const std::int64_t nv = std::int64_t{nv0} + std::int64_t{per_edge} * ne0 + std::int64_t{per_face} * nf0;
  const std::int64_t nf = std::int64_t{n} * n * nf0;
  if (nv > std::numeric_limits<Index>::max() || nf > std::numeric_limits<Index>::max())
    throw std::invalid_argument("subdivide_uniform: the result would exceed 2^31-1 elements");

  Mesh out;
  out.V.resize(static_cast<Eigen::Index>(nv), 3);
  out.F.resize(static_cast<Eigen::Index>(nf), 3);
  out.V.topRows(nv0) = mesh.V;

  // Edge points: point k (1..n-1) of edge e lies at k/n from edges(e, 0) (the smaller index)
  // towards edges(e, 1).
  const Index edge_base = nv0;
  for (Index e = 0; e < ne0; ++e) {
    const Eigen::RowVector3d a = mesh.V.row(topology.edges(e, 0));
    const Eigen::RowVector3d b = mesh.V.row(topology.edges(e, 1));
    for (Index k = 1; k < n; ++k) {
      const double t = static_cast<double>(k) / n;
      out.V.row(edge_base + e * per_edge + (k - 1)) = (1.0 - t) * a + t * b;
    }
  }
  const Index face_base = edge_base + ne0 * per_edge;

  // Per face, lattice point (i, j) with i, j >= 0, i + j <= n has barycentric coordinates
  // ((n - i - j) / n, i / n, j / n) with respect to the corners (c0, c1, c2).
  std::vector<Index> lattice(static_cast<std::size_t>((n + 1) * (n + 1)), -1);
  auto at = [&](Index i, Index j) -> Index& { return lattice[static_cast<std::size_t>(i * (n + 1) + j)]; };
  // Point at t/n along the face edge from corner `from` to corner `to`, edge index e.
  auto edge_point = [&](Index e, Index from, Index t) {
    const bool forward = topology.edges(e, 0) == from;
    const Index k = forward ? t : n - t;
    return edge_base + e * per_edge + (k - 1);
  };
  Index next_face_row = 0;
  for (Index f = 0; f < nf0; ++f) {
    const Index c0 = mesh.F(f, 0), c1 = mesh.F(f, 1), c2 = mesh.F(f, 2);
    at(0, 0) = c0;
    at(n, 0) = c1;
    at(0, n) = c2;
    // face_edges(f, k) joins corners k and (k + 1) % 3.
    const Index e01 = topology.face_edges(f, 0), e12 = topology.face_edges(f, 1), e20 = topology.face_edges(f, 2);
    for (Index t = 1; t < n; ++t) {
      at(t, 0) = edge_point(e01, c0, t);      // c0 -> c1
      at(n - t, t) = edge_point(e12, c1, t);  // c1 -> c2
      at(0, n - t) = edge_point(e20, c2, t);  // c2 -> c0
    }
    const Eigen::RowVector3d p0 = mesh.V.row(c0), p1 = mesh.V.row(c1), p2 = mesh.V.row(c2);
    Index inner = face_base + f * per_face;
    for (Index i = 1; i < n; ++i) {
      for (Index j = 1; i + j < n; ++j) {
        const double w1 = static_cast<double>(i) / n, w2 = static_cast<double>(j) / n;
        out.V.row(inner) = (1.0 - w1 - w2) * p0 + w1 * p1 + w2 * p2;
        at(i, j) = inner++;
      }
    }
    // Triangles with the input face's orientation: "up" (i, j), (i+1, j), (i, j+1) and
    // "down" (i+1, j), (i+1, j+1), (i, j+1).
    for (Index j = 0; j < n; ++j) {
      for (Index i = 0; i + j < n; ++i) {
        out.F.row(next_face_row++) << at(i, j), at(i + 1, j), at(i, j + 1);
        if (i + j + 1 < n) out.F.row(next_face_row++) << at(i + 1, j), at(i + 1, j + 1), at(i, j + 1);
      }
    }
  }
  return out;
}

Mesh make_large_test_mesh() {
  const Mesh base = read_mesh(data_dir() / "armadillo-43k.obj");
  return subdivide_uniform(base, 5);
}

bool report_topology(const Mesh& mesh, std::ostream& out) {
  const Topology t = build_topology(mesh.F, mesh.num_vertices());
  const bool ok = t.is_closed() && t.is_manifold() && t.is_oriented;
  out << "mesh: " << mesh.num_vertices() << " vertices, " << mesh.num_faces() << " faces, " << t.num_edges()
      << " edges; " << (t.is_manifold() ? "manifold" : "NOT manifold") << ", "
      << (t.boundary_loops.empty() ? "closed" : std::to_string(t.boundary_loops.size()) + " boundary loops") << ", "
      << (t.is_oriented ? "oriented" : "NOT oriented") << ", components " << t.num_components << ", genus "
      << t.genus() << (ok ? "" : "  <-- expected a closed oriented manifold") << '\n';
  return ok;
}

}  // namespace vertexflow::bench
