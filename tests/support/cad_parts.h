// Thin perforated solids tessellated the way CAD exporters tessellate them (issue 31): each
// planar face triangulated from its outline and hole polygons alone (a constrained Delaunay
// triangulation without Steiner points, so long thin fans run from the rims across the face
// and the outline's corners reach valences of 20 and more), each cylindrical hole wall one
// strip of two triangles per chord, the chords set by a chord tolerance (fewer on small
// holes). With the plate a fraction of an edge thick, most faces are slivers.
#pragma once

#include "vertexflow/mesh.h"

namespace vertexflow::test {

struct CadPlateOptions {
  enum class Outline { Rectangle, Disc };
  enum class Hole { Round, Slot };
  Outline outline = Outline::Rectangle;
  Hole hole = Hole::Round;
  /// The outline: a width x height rectangle centred at the origin, or a disc of diameter width.
  double width = 100, height = 60;
  /// Holes placed at random without overlap (at least `spacing` between rims and to the outline).
  int holes = 110;
  double min_radius = 0.6, max_radius = 4.0, spacing = 0.8;
  /// A slot is a stadium: two half circles `slot_length` apart.
  double slot_length = 4.0;
  /// Chord tolerance of the tessellation: a circle of radius r gets
  /// ceil(pi / acos(1 - chord_tolerance / r)) segments (at least 6).
  double chord_tolerance = 0.08;
  /// The disc outline's segments.
  int outline_segments = 96;
  /// The plate's thickness as a fraction of the mesh's mean edge length (solved for: the walls'
  /// edges are part of the mean).
  double thickness_in_edges = 0.2;
  /// 0: a flat plate. Otherwise the plate is a curved face: its mid-surface wrapped around a
  /// cylinder of this radius (axis along y), its caps triangulated with interior points as
  /// exporters place them on a curved face: columns `sqrt(8 R chord_tolerance)` apart across
  /// the bend (the chord error), `row_spacing_factor` times that apart along the straight axis.
  double bend_radius = 0;
  double row_spacing_factor = 3;
  unsigned seed = 1;
};

/// A closed, oriented, manifold plate of genus `holes` (throws std::runtime_error if the holes
/// do not fit). Flat plates lie in z = +-t/2; bent ones between radii R -+ t/2 about the axis
/// (x = 0, z = -R).
Mesh cad_perforated_plate(const CadPlateOptions& options);

}  // namespace vertexflow::test
