// What every method that moves vertices shares (the flow, the fit, smooth mode, the unsharp
// baseline): the vertices it may not move (VertexConstraints) and the guard that repairs the
// faces a move would spoil (GuardOptions). Each method's options embed them once
// (FlowOptions, FitOptions, UnsharpOptions), so a caller sets them in one place per method and
// enhance.h sets them once for all.
#pragma once

#include "vertexflow/mesh.h"

#include <array>
#include <vector>

namespace vertexflow {

/// The vertices a method leaves where they are, bit for bit.
struct VertexConstraints {
  /// Keep boundary vertices where they are (paper, section 6).
  bool fix_boundary = true;
  /// Vertices held in place (indices into V).
  std::vector<Index> pinned;
  /// Edges (pairs of vertex indices, either order) that the flow treats as creases whatever
  /// their dihedral angle: a vertex on one slides only along it, and a vertex where three or
  /// more meet, or where one ends, stays. `enhance` fills it with texture seams and material
  /// boundaries (attributes.h) so that no vertex crosses into another chart. Pairs that are no
  /// edge of the mesh are ignored.
  std::vector<std::array<Index, 2>> crease_edges;
};

/// The guard that follows every solve of the flow and the fit: it repairs every flipped or
/// degenerate face, and every face whose radius ratio 2r/R (quality.h) ends below its floor,
///
///     floor(f) = min(min_quality, worst input quality of the faces around f's corners)
///                and, if f starts below min_quality, at most sliver_floor * f's input quality,
///
/// by halving the displacement of one corner of each bad face, repeatedly (like CGAL's
/// tangential relaxation step control). So a face that starts at or above min_quality ends at
/// or above it unless a worse face touches it; the worst face around a vertex never ends below
/// min(min_quality, the worst input face around it), except that slivers (faces starting below
/// min_quality) may lose up to the fraction 1 - sliver_floor of their quality. A face may thus
/// get worse than it started as long as the worst face it touches does not: the earlier rule
/// (no face below its own input quality) froze sliver-heavy meshes (a thin genus-121 plate with
/// 63% of its faces below 0.3: 89% of the vertices shortened, rho +0.00; now, with the flow's
/// sliver term of flow_energy.h, 17.5% shortened and rho +0.13). Neither solve keeps a quality
/// floor itself; without the floor, CAD creases produced 0.3% (fandisk) to 3% (spot) of faces
/// below 0.3 in the flow.
struct GuardOptions {
  /// See above. 0 disables the quality floor: only flipped and degenerate faces are repaired.
  /// The flow's faces below min_quality are also the slivers of F_sliver (flow_energy.h).
  double min_quality = 0.3;
  /// See above: the fraction of its input quality below which a sliver (a face that starts
  /// below min_quality) may not fall. 1 keeps every sliver at least as good as its worst
  /// neighbour at the input; 0 lets slivers go down to any positive area.
  double sliver_floor = 0.5;
  /// Halvings of a vertex's displacement before it is set back to its start.
  int max_halvings = 30;
};

/// What one method's guard did, summed over its solves.
struct GuardCounts {
  Index flipped_before_guard = 0;      ///< faces the unguarded solutions turned or degenerated
  Index low_quality_before_guard = 0;  ///< faces they left below their quality floor
};

/// Throws std::invalid_argument, message prefixed with `what` ("vertex flow", "fit to
/// reference", ...), unless min_quality and sliver_floor are in [0, 1] and max_halvings >= 1.
void validate_guard_options(const GuardOptions& options, const char* what);

/// Throws std::invalid_argument, message prefixed with `what`, for a pinned index outside
/// [0, num_vertices).
void validate_vertex_constraints(const VertexConstraints& constraints, Index num_vertices, const char* what);

}  // namespace vertexflow
