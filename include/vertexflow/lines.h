// Line drawings (issue 17): the view-dependent lines of a mesh as 3D polylines.
//
// Occluding contours (this file so far) are the zero set of g(p) = n(p) . (eye - p), with n the
// vertex normals (curvature.h) interpolated linearly over each face, so the set is one segment
// per face where g changes sign, its ends interpolated along the edges. With an orthographic
// view the eye is at infinity and g = n . (-view direction). Segments that share an edge
// crossing are chained into polylines; a polyline is closed when it returns to its first
// crossing. Hidden lines are not removed here: the renderer's depth buffer does that.
// Deterministic: the same polylines, in the same order, for any thread count.
#pragma once

#include "vertexflow/mesh.h"

#include <vector>

namespace vertexflow {

/// A viewer: perspective from `eye`, or orthographic looking along `direction` (unit or not).
struct View {
  bool orthographic = false;
  Eigen::Vector3d eye = Eigen::Vector3d::Zero();          ///< perspective: the eye point
  Eigen::Vector3d direction = Eigen::Vector3d(0, 0, -1);  ///< orthographic: the viewing direction
};

/// A chain of crossings in the mesh's units.
struct Polyline {
  Vertices points;      ///< consecutive points (rows)
  bool closed = false;  ///< the last point connects back to the first
};

/// The occluding contours of (V, F) seen from `view`, with per-vertex unit `normals` (#V x 3,
/// usually curvature.h's vertex_normals). A vertex where g is exactly 0 counts as front-facing
/// (g > 0 side), so no crossing falls on a vertex. Throws std::invalid_argument when the normals
/// are not #V x 3 or a face index is out of range.
std::vector<Polyline> occluding_contours(const Vertices& V, const Faces& F, const Vertices& normals, const View& view);

}  // namespace vertexflow
