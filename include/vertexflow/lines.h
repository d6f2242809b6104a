// Line drawings (issue 17): the feature lines of a mesh as 3D polylines with their types.
//
// Every line type is the zero set of a per-vertex scalar g, interpolated linearly over each
// face: one segment per face where g changes sign, its ends interpolated along the edges, kept
// where the type's test passes. Segments that share an edge crossing are chained into
// polylines; a polyline is closed when it returns to its first crossing. A vertex where g is
// exactly 0 counts as positive, so no crossing falls on a vertex.
//
// - Occluding contours: g = n . (eye - p) (perspective) or n . (-direction) (orthographic),
//   with n the vertex normals.
// - Suggestive contours (DeCarlo, Finkelstein, Rusinkiewicz and Santella 2003): zeros of the
//   radial curvature k_r = II(w, w) / |w|^2, w the view vector projected into the tangent plane,
//   where the surface faces the viewer (n . v > 0) and k_r increases towards the viewer. The
//   kept part is where tan(theta) D_w k_r >= suggestive_threshold / L^2 (theta the angle
//   between n and v, w unit): DeCarlo et al. 2004's derivative, weighted by tan(theta) as the
//   reference implementation rtsc does, so that lines seen head-on (unstable) fade first.
//   With this header's sign convention (curvature.h: D_x n = S x, a sphere positive),
//   D_w k_r = C(w, w, w) - 2 tau_r^2 cot(theta), tau_r = II(w, w_perp) the geodesic torsion,
//   C the curvature derivative; D_w k_r > 0 at k_r = 0 is a local minimum of n . v along w.
// - Ridges and valleys (Ohtake, Belyaev and Seidel 2004): ridges are zeros of
//   e1 = D_T1 k1 = C(T1, T1, T1) that are maxima of k1 along T1, where k1 > |k2| and
//   k1 >= ridge_threshold / L; valleys are zeros of e2 = D_T2 k2 that are minima of k2 along T2,
//   where k2 < -|k1| and -k2 >= ridge_threshold / L. The principal directions have no sign, so
//   e is compared across an edge after aligning the two ends' directions. Reversing the faces'
//   orientation turns ridges into valleys and back. A surface of revolution has no ridge or
//   valley along a parallel whose curvature is constant along its own direction: on a round
//   torus D_T1 k1 = D_T2 k2 = 0 everywhere, so it has none (the test uses an elliptic tube).
//
// L, the length scale of every threshold, is the bounding-box diagonal unless given, so a
// coarse mesh and a dense mesh of the same shape get the same lines for the same options, and
// the options are invariant under uniform scaling.
//
// Hidden lines are not removed here: render.h's depth buffer does that (line_drawing.h).
// Deterministic: the same polylines, in the same order, for any thread count.
#pragma once

#include "vertexflow/curvature.h"
#include "vertexflow/mesh.h"

#include <string_view>
#include <vector>

namespace vertexflow {

/// A viewer: perspective from `eye`, or orthographic looking along `direction` (unit or not).
struct View {
  bool orthographic = false;
  Eigen::Vector3d eye = Eigen::Vector3d::Zero();          ///< perspective: the eye point
  Eigen::Vector3d direction = Eigen::Vector3d(0, 0, -1);  ///< orthographic: the viewing direction
};

enum class LineType { Contour, SuggestiveContour, Ridge, Valley };

/// "contours", "suggestive-contours", "ridges", "valleys": the names of the SVG groups, the
/// CLI's --lines values and the JSON counts.
std::string_view line_type_name(LineType type);

/// A chain of crossings in the mesh's units.
struct Polyline {
  Vertices points;                    ///< consecutive points (rows)
  bool closed = false;                ///< the last point connects back to the first
  LineType type = LineType::Contour;  ///< which kind of line it is
};

struct LineOptions {
  bool contours = true;
  bool suggestive_contours = true;
  bool ridges = true;
  bool valleys = true;
  /// L in the thresholds below; 0 = the bounding-box diagonal of V.
  double length_scale = 0;
  /// Suggestive contours are kept where tan(theta) D_w k_r >= this / L^2. rtsc's default is
  /// 0.05 in units of its feature size; 20 / L^2 keeps the bunny's and the armadillo's
  /// prominent creases and drops most noise of a 6k-vertex remesh (chosen by eye on data/).
  double suggestive_threshold = 20;
  /// Ridges need k1 >= this / L, valleys -k2 >= this / L at the crossing: 25 / L is a radius
  /// of curvature of 4% of the diagonal.
  double ridge_threshold = 25;
  /// Curvature estimation for suggestive contours, ridges and valleys. One round of tensor
  /// smoothing, since the lines follow derivatives of curvature, which amplify noise.
  CurvatureOptions curvature{NormalWeighting::Max1999, 1};
  /// When > 0, the curvature is smoothed over a fixed distance instead of a fixed number of
  /// rings: sigma = smoothing_scale * L, with as many rounds of one-ring averaging as a
  /// Gaussian of that sigma needs at the mesh's mean edge length e (sigma^2 / (0.43 e^2), at
  /// least curvature.smoothing_rounds, at most 400; each round spreads by about 0.43 e^2 per
  /// axis). A coarse and a dense mesh then show the same features, not each its own noise.
  double smoothing_scale = 0;
};

/// The occluding contours of (V, F) seen from `view`, with per-vertex unit `normals` (#V x 3,
/// usually curvature.h's vertex_normals). Throws std::invalid_argument when the normals are not
/// #V x 3 or a face index is out of range.
std::vector<Polyline> occluding_contours(const Vertices& V, const Faces& F, const Vertices& normals, const View& view);

/// The suggestive contours seen from `view` (see above), from the curvature of (V, F) and its
/// derivative. `threshold` is in units of 1 / length^2 (suggestive_threshold / L^2). Throws
/// std::invalid_argument for sizes that do not match or a face index out of range.
std::vector<Polyline> suggestive_contours(const Vertices& V, const Faces& F, const Curvature& curvature,
                                          const CurvatureDerivative& derivative, const View& view, double threshold);

/// Ridges and valleys (see above), view-independent; `threshold` in units of 1 / length
/// (ridge_threshold / L). Each polyline's type says which. Throws as suggestive_contours.
std::vector<Polyline> ridges_and_valleys(const Vertices& V, const Faces& F, const Curvature& curvature,
                                         const CurvatureDerivative& derivative, double threshold, bool ridges = true,
                                         bool valleys = true);

/// Every line type that `options` asks for, seen from `view`: contours first, then suggestive
/// contours, ridges and valleys. Estimates the curvature and its derivative when a type needs
/// them. Any triangle mesh (a non-manifold one is estimated on its manifold split, as in
/// curvature.h). Throws std::invalid_argument for a face index out of range or a negative
/// threshold or length scale.
std::vector<Polyline> feature_lines(const Vertices& V, const Faces& F, const View& view,
                                    const LineOptions& options = {});

}  // namespace vertexflow
