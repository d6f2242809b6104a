// Internal: vertex orderings that keep a mesh's neighbours close in memory.
//
// The flow's operator gathers over one-rings; in a mesh's own order the neighbours of a vertex
// can be anywhere in memory (subdivided meshes, amo.off). Measured: the iteration took 2-3x
// longer per vertex on those meshes than on one whose file order is local (horse-48k).
#pragma once

#include "vertexflow/mesh.h"
#include "vertexflow/topology.h"

#include <algorithm>
#include <cstdint>
#include <vector>

namespace vertexflow {

/// The low 21 bits of v spread to every third bit of 63: one axis of a Morton code.
inline std::uint64_t morton_spread_21(std::uint64_t v) {
  v &= 0x1fffffULL;
  v = (v | v << 32) & 0x1f00000000ffffULL;
  v = (v | v << 16) & 0x1f0000ff0000ffULL;
  v = (v | v << 8) & 0x100f00f00f00f00fULL;
  v = (v | v << 4) & 0x10c30c30c30c30c3ULL;
  v = (v | v << 2) & 0x1249249249249249ULL;
  return v;
}

/// The Morton code of a point given in grid units, t = (p - low) * 2097151 / (high - low) per
/// axis: each coordinate's cell of the 2^21 grid, clamped to it; a negative or non-finite
/// coordinate goes to cell 0 (an arbitrary but fixed place: a NaN cast to an integer would be
/// undefined).
inline std::uint64_t morton_code_of_cells(double tx, double ty, double tz) {
  const auto cell = [](double t) { return t >= 0 ? static_cast<std::uint64_t>(std::min(t, 2097151.0)) : 0; };
  return morton_spread_21(cell(tx)) | morton_spread_21(cell(ty)) << 1 | morton_spread_21(cell(tz)) << 2;
}

/// Vertices sorted by the Morton code of their position (21 bits per axis), ties by index.
std::vector<Index> space_filling_order(const Vertices& P);

/// Breadth-first (Cuthill-McKee) order of the vertex graph, each component started from its
/// first vertex in `seed_order`. Started from the Morton order (a vertex near a corner of the
/// bounding box) the breadth-first levels stay short, so every neighbour of a vertex is within
/// about one level's width of it in memory, a few hundred to a few thousand vertices, and the
/// one-ring gathers stay in the L2 cache; in Morton order a fraction of them jump far (the
/// curve's seams). Measured per iteration of the flow's solver, 1 thread: amo 11.6 -> 8.5 ms;
/// armadillo-1M, 2 threads: 126 -> 77 ms.
std::vector<Index> breadth_first_order(const Topology& topology, const std::vector<Index>& seed_order);

}  // namespace vertexflow
