// A raw range scan made from a clean one (issue 31): what a scanner's merge leaves before any
// clean-up, so that `remesh` can be tested on it without committing a large file. Used by
// test_remesh, test_apps and bench/make_raw_scan.cpp (which writes it to a file).
//
// Sizes are in units of the target edge length L that a remesh to `target_vertices` vertices
// would use (edge_length_for_vertex_count of the input's area), so the defects sit where the
// remesher has trouble: below, at and above one target edge.
#pragma once

#include "vertexflow/mesh.h"

namespace vertexflow::test {

struct RawScanOptions {
  /// Midpoint subdivisions (each face into 4, same surface) before anything is cut, so that the
  /// input is as much denser than the remesh as a raw scan is (437k vertices to 6000 in issue 31).
  int subdivisions = 0;
  /// The remesh the defects are scaled for.
  Index target_vertices = 6000;
  /// Holes cut into the surface: all faces whose centroid lies within r of a random face's
  /// centroid, r log-uniform in [hole_radius_min, hole_radius_max] target edges (the smallest
  /// remove one face: a rim of 3 input edges, shorter than one target edge).
  int holes = 320;
  double hole_radius_min = 0.1;
  double hole_radius_max = 2.5;
  /// Floating pieces near the surface, of size s log-uniform in [piece_size_min,
  /// piece_size_max] target edges: a copy of the surface patch within s of a random face (one
  /// or two random triangles when s is below the input's edge), moved off the surface along
  /// the normal by 0.3 to 2 target edges, each vertex by up to half an input edge more.
  int pieces = 120;
  double piece_size_min = 0.05;
  double piece_size_max = 3.0;
  /// Share of the holes whose rims get slivers: on 70 % of their rim edges a triangle whose
  /// apex sits 1e-5 to 3e-2 edge lengths off the edge's midpoint, inside the hole.
  double sliver_hole_share = 0.5;
  unsigned seed = 31;
};

struct RawScan {
  Mesh mesh;
  double target_edge = 0;         ///< L, input units
  Index holes = 0;                ///< holes cut (some merge into one boundary loop)
  Index pieces = 0;               ///< floating pieces added
  Index pieces_below_target = 0;  ///< of those, smaller than L across
  Index slivers = 0;              ///< rim slivers added
};

/// The raw scan made from `clean` (a manifold, oriented mesh). Deterministic for a seed.
RawScan make_raw_scan(const Mesh& clean, const RawScanOptions& options = {});

}  // namespace vertexflow::test
