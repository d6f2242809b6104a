// Colour maps for per-vertex scalars.
#pragma once

#include "vertexflow/mesh.h"

namespace vertexflow {

/// A symmetric value range [-limit, limit] (or [0, limit] for non-negative data) chosen
/// robustly: limit is the larger of |5th percentile| and |95th percentile|, so a few extreme
/// vertices do not wash out the map. Falls back to the maximum magnitude, then to 1, when the
/// percentiles are zero.
double robust_color_limit(const Eigen::VectorXd& values);

/// Diverging map (Moreland's cool-warm end points): -limit -> blue, 0 -> white,
/// +limit -> red, clamped outside; the paper's Fig. 10 convention (red positive, blue
/// negative).
Colors diverging_colors(const Eigen::VectorXd& values, double limit);

}  // namespace vertexflow
