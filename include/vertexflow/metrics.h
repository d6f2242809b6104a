// Measurements of what the flow did (docs/metrics.md is the contract).
#pragma once

#include "vertexflow/curvature.h"
#include "vertexflow/mesh.h"
#include "vertexflow/topology.h"

#include <vector>

namespace vertexflow {

/// Spearman rank correlation of two equally long samples (ties get their average rank);
/// 0 when either sample is constant or shorter than 2.
double spearman_correlation(const Eigen::VectorXd& a, const Eigen::VectorXd& b);

/// Per-vertex sampling density 1 / A_i, A_i = one third of the incident triangle areas
/// (0 for a vertex with no area).
Eigen::VectorXd vertex_density(const Vertices& V, const Faces& F);

/// Redistribution: Spearman rho between the surface's curvature magnitude |k1| + |k2| per vertex
/// (`surface_curvature`, e.g. of the input at the same vertices) and the vertex density of V.
double redistribution_rho(const Eigen::VectorXd& surface_curvature, const Vertices& V, const Faces& F);

/// Uniformity of the per-edge approximation error delta_e = f_em(e) / 8 (Eq. 2-4 with the
/// surface's curvature frozen per vertex, edges at the positions V).
struct EdgeErrorStats {
  double mean = 0;
  double max_over_mean = 0;
  double coefficient_of_variation = 0;  ///< std / mean
};
EdgeErrorStats edge_error_stats(const Vertices& V, const Topology& topology, const Curvature& surface);

/// The same with the surface's curvature given per vertex of V as the tensor K_i of
/// Curvature::absolute_tensor (e.g. a reference surface's tensors interpolated at the vertices,
/// compare.h): delta_e = (e^T K_i e + e^T K_j e) / 16. `surface_tensors` has one entry per
/// vertex; throws std::invalid_argument otherwise.
EdgeErrorStats edge_error_stats(const Vertices& V, const Topology& topology,
                                const std::vector<Eigen::Matrix3d>& surface_tensors);

}  // namespace vertexflow
