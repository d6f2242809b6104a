// The positions of a mesh's boundary vertices, for tests that check a boundary is kept bit for
// bit (simplify, lod).
#pragma once

#include "vertexflow/mesh.h"
#include "vertexflow/topology.h"

#include <array>
#include <cstddef>
#include <set>

namespace vertexflow::test {

using Point = std::array<double, 3>;

inline std::set<Point> boundary_points(const Mesh& mesh) {
  const Topology topology = build_topology(mesh.F, mesh.num_vertices());
  std::set<Point> points;
  for (Index v = 0; v < mesh.num_vertices(); ++v)
    if (topology.is_boundary_vertex[static_cast<std::size_t>(v)])
      points.insert({mesh.V(v, 0), mesh.V(v, 1), mesh.V(v, 2)});
  return points;
}

}  // namespace vertexflow::test
