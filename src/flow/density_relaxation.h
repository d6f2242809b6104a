// Internal to the flow stage: the density-weighted centroidal passes of FlowOptions::density
// (flow.h), which are not part of the paper's energy.
#pragma once

#include "vertexflow/curvature.h"
#include "vertexflow/flow.h"
#include "vertexflow/topology.h"

#include <Eigen/Core>

#include <vector>

namespace vertexflow {

/// The sizing density of every vertex, (epsilon + |k1| + |k2|)^exponent, for curvature in units
/// of the mean edge length (the flow's normalised units, so the density is dimensionless).
Eigen::VectorXd sizing_density(const Curvature& curvature, const DensityRelaxation& options);

/// One pass's proposal: every row i of `rows` moves by options.step of the way from X_i to the
/// centroid of its faces' centroids weighted by face area times face density (the mean of its
/// corners' `density`). Other rows keep X. The face areas are X's, so repeated passes equalise
/// density times area around every vertex, which is what concentrates vertices where the
/// density is high (a centroidal Voronoi relaxation, restricted to the fixed one-rings).
/// Parallel over rows, deterministic.
Vertices density_pass_proposal(const Vertices& X, const Faces& F, const Topology& topology,
                               const Eigen::VectorXd& density, const std::vector<Index>& rows, double step);

}  // namespace vertexflow
