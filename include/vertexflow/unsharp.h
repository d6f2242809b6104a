// Geometric unsharp masking, the classical feature-enhancement baseline the vertex flow is
// compared with: v' = v + w (v - S^k(v)), where S is uniform Laplacian smoothing (each vertex
// replaced by the mean of its one-ring neighbours, Jacobi style) applied k times. Guskov,
// Sweldens and Schroeder, "Multiresolution signal processing for meshes" (SIGGRAPH 1999), and
// MeshLab's "UnSharp Mask Geometry" filter (vcglib) are the references.
//
// Conventions
// - Connectivity is unchanged; only positions move. w = 0 is the identity.
// - Fixed vertices (boundary when fix_boundary, pinned, isolated) keep their positions in the
//   result and also during the smoothing, so they act as Dirichlet conditions for their
//   neighbours' smoothed positions.
// - The map is affine in V: translating, rotating or uniformly scaling the input transforms the
//   result in the same way (no normalisation is needed, unlike the flow).
// - Nothing limits the displacement: large w or k can fold faces (the enhance report counts
//   flipped faces). The flow's guard is deliberately not applied, so the baseline stays the
//   textbook filter.
// - Differences from MeshLab's filter: MeshLab's smoothing averages each vertex with itself
//   once and each neighbour once per shared face, and moves boundary vertices along the
//   boundary; here S is the plain one-ring mean with fixed boundary, as in the Laplacian used
//   by the paper's other terms. MeshLab's "original weight" is fixed at 1.
// - Non-manifold input, as for the flow (flow.h): the mesh is smoothed as its manifold split
//   (manifold_split.h), whose cut edges are boundaries, with the vertices that have several
//   copies held bit for bit. The smoothing needs no orientation, so a manifold mesh whose
//   faces disagree in orientation is smoothed as it is. refuse_non_manifold keeps the old
//   refusal.
#pragma once

#include "vertexflow/guard.h"
#include "vertexflow/manifold_split.h"
#include "vertexflow/mesh.h"

#include <vector>

namespace vertexflow {

struct UnsharpOptions {
  /// w: how much of the detail v - S^k(v) is added back. MeshLab's default, 0.3.
  double weight = 0.3;
  /// k: rounds of uniform Laplacian smoothing that define the detail. MeshLab's default, 5.
  int smoothing_iterations = 5;
  /// Boundary (unless constraints.fix_boundary is false) and pinned vertices stay where they are.
  VertexConstraints constraints;
  /// Refuse (std::invalid_argument) a non-manifold mesh instead of smoothing its manifold
  /// split (the CLI's --strict).
  bool refuse_non_manifold = false;
};

struct UnsharpResult {
  Vertices V;                ///< new positions; faces are unchanged
  Index fixed_vertices = 0;  ///< boundary, pinned, isolated and held non-manifold vertices
  /// Non-manifold input: what its manifold split held and cut (reversed_faces is always 0).
  ManifoldSplitCounts non_manifold;
};

/// Applies the unsharp mask to (V, F). Throws std::invalid_argument for an empty mesh, a
/// non-manifold one with refuse_non_manifold, a negative iteration count, a non-finite weight
/// or a pinned index out of range.
UnsharpResult unsharp_mask(const Vertices& V, const Faces& F, const UnsharpOptions& options = {});

}  // namespace vertexflow
