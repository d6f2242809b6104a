// Exaggerated shading (issue 17): Rusinkiewicz, Burns and DeCarlo, "Exaggerated Shading for
// Depicting Shape and Detail", SIGGRAPH 2006, computed per vertex on the CPU. The renderer draws
// it as per-vertex greys with lighting off (render.h, RenderShading::Exaggerated).
//
// The method (the paper's multi-scale local toon shading, its formula for arbitrary 3D surfaces)
// - Normals at b + 1 scales: n_0 are the mesh's vertex normals (curvature.h), n_i for i >= 1
//   those normals smoothed by a Gaussian of standard deviation sigma_i = sigma_1 2^(i - 1)
//   along the surface, then normalised.
// - At each scale i < b the light is made grazing with respect to the next-coarser surface: l is
//   projected into the plane perpendicular to n_{i+1} and normalised, giving l_{i+1}, and the
//   detail term is the toon-shaded c_i = clamp_[-1,1](a n_i . l_{i+1}), with a the exaggeration.
//   Where l is parallel to n_{i+1} the projection has no direction and c_i = 0.
// - The coarsest normals see the light itself: c_b = clamp_[-1,1](a n_b . l) (the overall shape).
// - shade = 1/2 + 1/2 sum_{i=0..b} k_i c_i with the weights k_i normalised to sum to 1, so shade
//   is in [0, 1]: 1/2 is mid grey, where every term is 0.
//
// Smoothing: sigma_1 is given in mean edge lengths, so the finest scale resolves the mesh's own
// detail and the number of passes below does not grow with the resolution, whereas a fraction of
// the bounding-box diagonal would need (diagonal / edge)^2 times more passes on dense meshes
// (see ExaggeratedShadingOptions::sigma).
// The Gaussians are approximated by repeated area-weighted averaging over each vertex's closed
// one-ring (itself and its neighbours); a pass spreads a normal by a per-axis variance s^2
// measured on the mesh (half the mean weighted squared distance of a pass), so scale i takes
// round(sigma_i^2 / s^2) passes in all, each scale continuing from the previous one.
//
// Conventions
// - The light is a direction in mesh coordinates pointing from the surface towards the light
//   (n . l > 0 is lit); it need not be unit.
// - Deterministic: the same shades, bit for bit, for any thread count. Rotating and translating
//   the mesh and the light together, scaling the mesh, or renumbering its vertices gives the
//   same shades (renumbered) up to rounding.
// - Works on any triangle list (non-manifold, open, several components): smoothing follows the
//   edges. A vertex in no face keeps its raw normal (0, 0, 1) of vertex_normals.
#pragma once

#include "vertexflow/mesh.h"

#include <vector>

namespace vertexflow {

struct ExaggeratedShadingOptions {
  /// b: the number of detail terms c_0 .. c_{b-1}, each with its own smoothing scale; 0 leaves
  /// only the overall-shape term (toon shading of the raw normals). In [0, 8].
  int scales = 4;
  /// sigma_1, the smoothing of n_1, in mean edge lengths (> 0): with the default b = 4 the scales
  /// are 1, 2, 4 and 8 mean edge lengths. The work is about (sigma_1 2^(b-1))^2 / s^2 averaging
  /// passes over all vertices, s^2 ~ 0.43 squared edge lengths on a regular mesh: ~150 passes
  /// with the defaults (0.1 s for 100k faces on 2 cores), 4 times as many per further scale.
  double sigma = 1.0;
  /// a, the exaggeration (contrast) of every term, > 0. Larger values push each term to +-1,
  /// the toon-like look of the paper; a = 1 shades each scale like a Lambertian term.
  double exaggeration = 10.0;
  /// k_0 .. k_b, the weights of the b detail terms and of the overall-shape term, each >= 0 with
  /// a positive sum; they are normalised to sum to 1. Empty: every detail term 1 and the overall
  /// shape 2 (so the shape reads at the coarsest scale and the detail on top of it).
  std::vector<double> weights;
};

/// The shade in [0, 1] of every vertex of (V, F) lit from direction `light` (mesh coordinates,
/// towards the light). Empty for a mesh without vertices. Throws std::invalid_argument when
/// `light` is zero or not finite, an option is out of range (weights: wrong count, negative,
/// not finite, or summing to 0), V is not finite, or a face index is out of range or repeats
/// a vertex (build_topology).
Eigen::VectorXd exaggerated_shading(const Vertices& V, const Faces& F, const Eigen::Vector3d& light,
                                    const ExaggeratedShadingOptions& options = {});

}  // namespace vertexflow
