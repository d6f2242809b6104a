// What an input is, checked before a method that assumes its vertices lie on the true surface
// moves them (issue 30: "never worse without saying so").
//
// The paper's flow keeps the vertices on the input's facets and smooth mode fits them to patches
// through them: both take the vertices as samples of the true surface, as they are on scans,
// remeshes and subdivision output. Two common kinds of input break that assumption, and the
// methods then make the mesh worse (mean distance to the dense mesh, docs/method-notes.md,
// "Inputs held"):
//   - decimated meshes: QEM puts each vertex where the quadric is smallest, off the surface, and
//     leaves thin triangles; on `vertexflow simplify` outputs at 10% of the faces the flow raised
//     the mean distance by 11-55%, smooth mode by 26-100%;
//   - subdivision control meshes (cages): the limit surface lies inside the cage, away from its
//     vertices; smooth mode, whose patches bulge out through the vertices, raised the distance to
//     the limit surface by 9-47% on Loop and Catmull-Clark pairs made from data/.
// Geometry alone cannot tell such a mesh from one whose vertices do lie on a surface (a sphere's
// inscribed and best-fitting meshes are the same mesh at two scales). What it can tell:
//   - poor_face_fraction: the share of interior faces below quality 0.3 (triangle_quality,
//     quality.h), where a face is interior when none of its corners is on a boundary edge.
//     Decimation leaves such faces everywhere, remeshing and scanning do not: 4.0-20.5% on QEM
//     outputs of 9 data/ meshes at 10% and 25% of their faces (amo at 25%: 2.95%), 0-0.05% on
//     remeshes, at most 1.93% on the data/ meshes that are not decimated (fertility). Rim faces
//     are left out because a remesh of a scan with hundreds of holes far below its edge length
//     has needles around them and nowhere else (docs/remesh.md: 12.6% of the rim faces, 0% of
//     the interior ones, of a bunny scan with 650 holes); smooth mode gains 18% on it.
//   - sharp_edge_fraction: the share of interior edges whose two faces turn by more than
//     kSharpEdgeAngle (the methods' default feature angle). A cage is coarse for its shape, so
//     many of its edges turn that far: 11.4-100% on the cages of the pairs; at most 5.1% on the
//     remeshes (the 6k remesh of armadillo) and 3.7% on the other data/ meshes (fandisk's
//     creases). A mesh can be the cage of one surface and a coarse remesh of another: meshes this
//     coarse are held either way (docs/method-notes.md says what that costs).
// Conventions: dimensionless, the same for any rigid motion or uniform scale; deterministic.
#pragma once

#include "vertexflow/mesh.h"
#include "vertexflow/topology.h"

namespace vertexflow {

/// Faces below quality 0.3 (triangle_quality) above this share: decimated.
inline constexpr double kMaxPoorFaceFraction = 0.025;
/// Interior edges sharper than kSharpEdgeAngle above this share: a subdivision control mesh.
inline constexpr double kMaxSharpEdgeFraction = 0.08;
/// Degrees between the normals of an edge's two faces above which the edge counts as sharp.
inline constexpr double kSharpEdgeAngle = 40.0;

struct InputCheckOptions {
  /// Thresholds in [0, 1]; 1 never holds for that reason.
  double max_poor_face_fraction = kMaxPoorFaceFraction;
  double max_sharp_edge_fraction = kMaxSharpEdgeFraction;
};

/// Why an input is held: not at all, decimated (poor_face_fraction), a subdivision control mesh
/// (sharp_edge_fraction), or already fitted (its provenance, provenance.h; smooth mode only).
enum class HoldReason { None, Decimated, ControlMesh, AlreadyFitted };

/// The reason as reports and warnings name it: null's stand-in "none", "decimated",
/// "subdivision control mesh", "already fitted".
const char* hold_reason_name(HoldReason reason);

struct InputCheck {
  /// Share of the interior faces (no corner on a boundary edge) below quality 0.3, in [0, 1];
  /// over all faces when every face has a corner on a boundary edge.
  double poor_face_fraction = 0;
  Index interior_faces = 0;        ///< faces with no corner on a boundary edge
  Index rim_faces = 0;             ///< faces with a corner on a boundary edge
  double sharp_edge_fraction = 0;  ///< share of interior edges sharper than kSharpEdgeAngle
  Index interior_edges = 0;        ///< edges with exactly two faces (the fraction's denominator)
  /// Decimated when poor_face_fraction exceeds its threshold, else a control mesh when
  /// sharp_edge_fraction exceeds its own; None otherwise.
  HoldReason reason = HoldReason::None;
};

/// Measures (V, F) as above. A boundary edge is an edge of exactly one face with three distinct
/// corners. Faces with a repeated vertex or zero area count in the quality share (their quality
/// is 0) and not among the interior edges' faces. Throws std::invalid_argument
/// for a threshold outside [0, 1].
/// `topology`, when given, must be build_topology(F, V.rows()): the edges are then taken from it
/// instead of found again, with the same result.
InputCheck check_input(const Vertices& V, const Faces& F, const InputCheckOptions& options = {},
                       const Topology* topology = nullptr);

}  // namespace vertexflow
