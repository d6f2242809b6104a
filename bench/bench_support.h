// Shared pieces of the benchmarks: the ~1M-vertex test mesh and where the bundled data lives.
#pragma once

#include "vertexflow/mesh.h"
#include "vertexflow/topology.h"

#include <filesystem>
#include <iosfwd>

namespace vertexflow::bench {

/// The repository's data/ folder (compile definition VERTEXFLOW_DATA_DIR).
std::filesystem::path data_dir();

/// Uniform subdivision: every edge is split into `segments` equal parts and every triangle into
/// segments^2 triangles with the same orientation. Points on a shared edge are computed once
/// and shared by both faces, so a closed manifold input gives a closed manifold result with
/// V = V0 + (segments - 1) E + (segments - 1)(segments - 2)/2 F vertices and segments^2 F faces.
/// Vertex order: the input's vertices, then the edge points (edge by edge), then the points
/// inside each face (face by face). Colours and vertex properties are not carried over.
Mesh subdivide_uniform(const Mesh& mesh, int segments);

/// data/armadillo-43k.obj (43,243 V / 86,482 F) subdivided 1-to-25 (segments = 5):
/// 1,081,027 vertices and 2,162,050 faces.
Mesh make_large_test_mesh();

/// Builds the topology of `mesh` and prints one line with its counts and whether it is closed,
/// manifold and consistently oriented. Returns true when it is all three.
bool report_topology(const Mesh& mesh, std::ostream& out);

}  // namespace vertexflow::bench
