// Triangle quality (docs/metrics.md, "Mesh quality").
//
// Radius ratio q = 2 r / R (inradius r, circumradius R), in [0, 1]: 1 for an equilateral
// triangle, 0 for a degenerate one (Pebay and Baker 2003). Computed as
// q = (b + c - a)(c + a - b)(a + b - c) / (a b c) from the edge lengths a, b, c, which is
// exact for valid triangles and clamps rounding noise of needles to 0. Scale- and
// rotation-invariant. The paper's Fig. 5 uses the same measure.
#pragma once

#include "vertexflow/mesh.h"

#include <array>

namespace vertexflow {

/// Radius ratio 2r/R of the triangle (p0, p1, p2).
double triangle_quality(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, const Eigen::Vector3d& p2);

/// Radius ratio 2r/R of each face (#F).
Eigen::VectorXd triangle_quality(const Vertices& V, const Faces& F);

/// Summary of a set of per-face qualities.
struct QualityStats {
  double min = 0;
  double mean = 0;
  double p5 = 0;                             ///< 5th percentile (nearest rank)
  double fraction_below_0_3 = 0;             ///< share of faces with q < 0.3
  std::array<std::int64_t, 10> histogram{};  ///< counts in [0, 0.1), ..., [0.9, 1.0]
};

/// Statistics of `quality` (values in [0, 1]); all zero for an empty input.
QualityStats summarize_quality(const Eigen::VectorXd& quality);

}  // namespace vertexflow
