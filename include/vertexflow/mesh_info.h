// A summary of a mesh: what `vertexflow info` prints.
#pragma once

#include "vertexflow/mesh.h"
#include "vertexflow/quality.h"
#include "vertexflow/topology.h"

namespace vertexflow {

struct MeshInfo {
  Index num_vertices = 0;
  Index num_faces = 0;
  Index num_edges = 0;
  BoundingBox bounding_box;
  double diagonal = 0;
  double edge_length_mean = 0;
  double edge_length_min = 0;
  double edge_length_max = 0;
  double surface_area = 0;
  Index boundary_loops = 0;
  Index components = 0;
  std::int64_t euler_characteristic = 0;
  std::int64_t genus = -1;  ///< -1 when undefined (non-manifold or inconsistently oriented)
  bool manifold = true;
  bool oriented = true;
  bool closed = true;
  Index non_manifold_edges = 0;
  Index non_manifold_vertices = 0;
  QualityStats quality;
};

/// Summarises a mesh whose topology has been built.
MeshInfo describe_mesh(const Mesh& mesh, const Topology& topology);

}  // namespace vertexflow
