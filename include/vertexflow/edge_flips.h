// Data-dependent edge flips (issue 16; the paper's section 4.4 gives users the option of edge
// flips alongside the flow). The vertex count and positions stay; only the diagonal of some
// pairs of faces changes, so this changes connectivity and is opt-in (`enhance --edge-flips`).
//
// An interior edge (a, b) with faces (a, b, c) and (b, a, d) is flipped to (c, d), giving the
// faces (a, d, c) and (d, b, c), when that lowers the squared distance between the pair and a
// target surface T (a dense reference, or the smooth estimate of fit.h), integrated over the
// pair: E(f) = area(f) * mean over the 4 centroids of f's 2 x 2 subdivision of the squared
// distance to T. A flip is made when it lowers E of the pair by more than `min_gain` of its value,
// and never when
// - the edge is on a boundary or non-manifold (not exactly two faces, oppositely oriented), or
//   (c, d) is an edge already, or a or b would be left with fewer than three faces (one on a
//   boundary), or the pair lies on T to a millionth of its longest edge (nothing to gain but
//   rounding noise);
// - a new face's normal points against either old face's normal (the pair would fold), or a new
//   face's radius ratio (quality.h) is below min(min_quality, the old pair's worst).
// Each pass evaluates every edge against the same faces, then flips the best candidates first,
// each face at most once per pass; passes repeat until none flips or max_passes. Deterministic
// (ties broken by the edge's first face and corner): the same faces for any thread count.
// Orientation is kept: every new face has the winding of the pair it replaces.
#pragma once

#include "vertexflow/distance.h"
#include "vertexflow/mesh.h"

#include <array>
#include <vector>

namespace vertexflow {

struct EdgeFlipOptions {
  /// The quality floor of new faces (radius ratio), as GuardOptions::min_quality (guard.h).
  double min_quality = 0.3;
  /// The relative decrease of the pair's E a flip must bring (it keeps rounding noise and
  /// near-planar pairs from flipping back and forth).
  double min_gain = 0.05;
  int max_passes = 5;
  /// Edges never flipped (vertex pairs, either order): texture seams and boundaries between
  /// faces of different materials or labels, so that every face keeps one chart and one label.
  std::vector<std::array<Index, 2>> fixed_edges;
};

struct EdgeFlipReport {
  Index flips = 0;
  int passes = 0;
  /// sqrt(sum E / area): the area-weighted RMS distance from the mesh to T at the data points,
  /// before and after, in the meshes' units.
  double rms_before = 0, rms_after = 0;
};

struct EdgeFlipResult {
  Faces F;
  EdgeFlipReport report;
};

/// Flips edges of (V, F) towards the surface behind `target`, as described above. With
/// `slot_normals` (#F x 3, say the input's face normals when (V, F) is a result of the flow),
/// a flip is also refused when a new face would point against the normal of its slot, so that
/// faces_turned_over against that mesh stays 0. Throws std::invalid_argument for an empty mesh,
/// an index out of range, slot normals not #F x 3, or options out of range (min_quality in
/// [0, 1], min_gain >= 0, max_passes >= 1).
EdgeFlipResult flip_edges_toward(const Vertices& V, const Faces& F, const DistanceQuery& target,
                                 const EdgeFlipOptions& options = {}, const Vertices* slot_normals = nullptr);

/// Faces of (V, F) whose normal points against the normal of face (V0, F0) with the same
/// index: the flip count of compare.h (a face turned by more than 90 degrees) for a result of
/// flip_edges_toward, whose faces differ from the input's. A flip keeps both faces' indices, and
/// each new face lies over the quad of the pair it replaces, whose faces it must not point
/// against. Degenerate faces, and faces degenerate in (V0, F0), are not counted. Throws
/// std::invalid_argument for different vertex or face counts. (Vertex normals are no substitute:
/// faces of the paper's flow at tight bends, not flipped by compare.h's rule, pointed against the
/// normals of all three of their corners.)
Index faces_turned_over(const Vertices& V0, const Faces& F0, const Vertices& V, const Faces& F);

}  // namespace vertexflow
