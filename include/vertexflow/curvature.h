// Per-vertex normals, areas, principal curvatures and principal directions.
//
// The estimator is Rusinkiewicz, "Estimating curvatures and their derivatives on triangle
// meshes" (3DPVT 2004), which the paper adopts (section 4.4): a least-squares fit of the
// second fundamental form per face from the differences of the vertex normals along its three
// edges, transported into each vertex's tangent frame and averaged with Voronoi weights.
//
// Conventions (every function in this header)
// - Normals: unit, oriented by the faces' orientation (counter-clockwise = front). For a
//   closed, consistently oriented mesh with positive signed volume they point outwards.
// - Sign: curvature is positive where the surface bends away from its normal, i.e. convex
//   with outward normals is positive. A sphere of radius R with outward normals has
//   k1 = k2 = +1/R; reversing every face's orientation flips every sign.
// - Order: k1 >= k2 (signed maximum and minimum curvature). Units: 1 / (length of V).
// - Directions: T1, T2 are unit vectors in the tangent plane with T1 x T2 = N; T1 belongs to
//   k1. Where k1 == k2 (umbilic) they are an arbitrary orthonormal tangent pair.
// - Mean curvature H = (k1 + k2) / 2 (so a unit sphere has H = 1), Gaussian K = k1 k2.
// - Boundary vertices get values from their one-sided neighbourhood only: finite, but biased
//   (on hemisphere.off the boundary ring underestimates 1/R by a few percent; see
//   tests/curvature). Vertices with no non-degenerate incident face get k1 = k2 = 0, the
//   normal +z and an arbitrary frame. No NaN or inf is ever returned for finite input.
// - Input: any triangle mesh. A non-manifold or inconsistently oriented one is estimated on its
//   manifold split (manifold_split.h: faces oriented per component, non-manifold edges cut):
//   a vertex whose faces form several fans takes the values of its largest fan's copy, and the
//   area of all its fans. Normals then follow the orientation most faces of a component had.
#pragma once

#include "vertexflow/mesh.h"
#include "vertexflow/topology.h"

#include <cmath>

namespace vertexflow {

/// How face normals are weighted into vertex normals.
enum class NormalWeighting {
  /// Max (1999): each corner's cross product divided by the squared lengths of its two edges;
  /// exact for vertices of a sphere. The reference implementation's choice (default).
  Max1999,
  /// Face area (the unnormalised face normal).
  Area,
  /// Corner angle.
  Angle,
};

/// Unit vertex normals (#V x 3).
Vertices vertex_normals(const Vertices& V, const Faces& F, NormalWeighting weighting = NormalWeighting::Max1999);

/// Per-corner Voronoi areas (#F x 3) by Meyer et al. 2003 "mixed" rule: the Voronoi region
/// for non-obtuse triangles; for an obtuse triangle half its area goes to the obtuse corner
/// and a quarter to each other corner. Rows sum to the face areas.
Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> corner_areas(const Vertices& V, const Faces& F);

/// Per-vertex mixed Voronoi areas (#V): the sum of the vertex's corner areas. They sum to
/// the surface area.
Eigen::VectorXd vertex_areas(const Vertices& V, const Faces& F);

struct CurvatureOptions {
  NormalWeighting normal_weighting = NormalWeighting::Max1999;
  /// Rounds of one-ring averaging of the curvature tensor (each vertex's tensor replaced by
  /// the area-weighted mean of its own and its neighbours' tensors, transported into its
  /// frame). 0 = the plain estimator, as in the paper. Smoothing lowers noise on scans at the
  /// price of blurring sharp creases.
  int smoothing_rounds = 0;
};

/// Principal curvatures of every vertex. See the conventions above.
struct Curvature {
  Eigen::VectorXd k1;    ///< maximum principal curvature (#V)
  Eigen::VectorXd k2;    ///< minimum principal curvature (#V), k2 <= k1
  Vertices T1;           ///< unit direction of k1 (#V x 3)
  Vertices T2;           ///< unit direction of k2 (#V x 3), T1 x T2 = N
  Vertices N;            ///< unit vertex normals used for the frames (#V x 3)
  Eigen::VectorXd area;  ///< mixed Voronoi area per vertex (#V)

  [[nodiscard]] Eigen::VectorXd mean() const { return 0.5 * (k1 + k2); }
  [[nodiscard]] Eigen::VectorXd gaussian() const { return k1.cwiseProduct(k2); }
  /// |k1| + |k2|: the curvature magnitude the flow's energies use.
  [[nodiscard]] Eigen::VectorXd absolute_sum() const { return k1.cwiseAbs() + k2.cwiseAbs(); }
  /// K_i = |k1| T1 T1^T + |k2| T2 T2^T of vertex i (3 x 3, symmetric positive semi-definite):
  /// the edge metric of the paper's Eq. 2 as a quadratic form, f_i(e) = e^T K_i e. Its trace
  /// is absolute_sum()[i].
  [[nodiscard]] Eigen::Matrix3d absolute_tensor(Index i) const {
    const Eigen::Vector3d t1 = T1.row(i).transpose(), t2 = T2.row(i).transpose();
    return std::abs(k1[i]) * t1 * t1.transpose() + std::abs(k2[i]) * t2 * t2.transpose();
  }
};

/// Estimates principal curvatures and directions (Rusinkiewicz 2004). Parallel over faces and
/// vertices, vectorised (AVX2 + FMA where the CPU has it, chosen at load time). The result does
/// not depend on the number of threads; the order of vertices and faces changes it only by
/// rounding (1e-9 relative in tests/curvature), and so does a CPU without AVX2 (no fused
/// multiply-adds). About 5 M vertices/s on 2 cores (docs/benchmarks.md).
Curvature principal_curvatures(const Vertices& V, const Faces& F, const Topology& topology,
                               const CurvatureOptions& options = {});

/// Convenience overload that builds the topology.
Curvature principal_curvatures(const Vertices& V, const Faces& F, const CurvatureOptions& options = {});

/// The derivative of curvature (Rusinkiewicz 2004, section 5): per vertex the symmetric 2 x 2 x 2
/// tensor C(x, y, z) = (D_x II)(y, z), the change of the second fundamental form II along the
/// tangent x, which line drawings need (ridges and valleys: D_T1 k1 = C(T1, T1, T1) = 0;
/// suggestive contours: the directional derivative of the radial curvature). Same sign
/// convention as the curvature above (a convex bump with outward normals has C(x, x, x) < 0
/// going outwards from its peak); units 1 / length^2. Fitted per face from the differences of
/// its corners' II along its edges (least squares in the Frobenius norm), transported into each
/// vertex's frame and averaged with the corner areas, as the curvature itself.
struct CurvatureDerivative {
  /// Per vertex (#V x 4): C(T1, T1, T1), C(T1, T1, T2), C(T1, T2, T2), C(T2, T2, T2), in the
  /// principal frame (T1, T2) of the Curvature it was estimated from.
  Eigen::Matrix<double, Eigen::Dynamic, 4, Eigen::RowMajor> C;

  /// C(x, y, z) at vertex i, for vectors x, y, z given in `curvature`'s frame as (x . T1, x . T2)
  /// and so on.
  [[nodiscard]] double evaluate(Index i, const Eigen::Vector2d& x, const Eigen::Vector2d& y,
                                const Eigen::Vector2d& z) const;
};

/// The derivative of `curvature` (principal_curvatures of the same mesh, any options). Parallel,
/// the same result for any thread count. Vertices without a usable face (degenerate, or folded
/// against the vertex normal) get 0. Throws std::invalid_argument when `curvature` or `topology`
/// is for another vertex count.
CurvatureDerivative curvature_derivative(const Vertices& V, const Faces& F, const Topology& topology,
                                         const Curvature& curvature);

}  // namespace vertexflow
