// feature_lines (lines.h): every requested line type of one view.
#include "lines/zero_set.h"
#include "vertexflow/topology.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace vertexflow {

std::string_view line_type_name(LineType type) {
  switch (type) {
    case LineType::Contour:
      return "contours";
    case LineType::SuggestiveContour:
      return "suggestive-contours";
    case LineType::Ridge:
      return "ridges";
    case LineType::Valley:
      return "valleys";
  }
  return "unknown";
}

std::vector<Polyline> feature_lines(const Vertices& V, const Faces& F, const View& view, const LineOptions& options) {
  lines_detail::check_line_input(V, F, {}, "feature lines");
  if (!(options.length_scale >= 0) || !(options.suggestive_threshold >= 0) || !(options.ridge_threshold >= 0) ||
      !(options.smoothing_scale >= 0))
    throw std::invalid_argument("feature lines: thresholds and the length scale must be >= 0");
  std::vector<Polyline> lines;
  if (F.rows() == 0) return lines;
  double L = options.length_scale;
  if (L == 0) L = bounding_box(V).diagonal();
  if (!(L > 0)) L = 1;  // every vertex in one point: nothing is curved
  const bool curved = options.suggestive_contours || options.ridges || options.valleys;
  std::optional<Curvature> curvature;
  CurvatureDerivative derivative;
  if (curved) {
    const Topology topology = build_topology(F, V.rows());
    CurvatureOptions curvature_options = options.curvature;
    if (options.smoothing_scale > 0) {
      const double sigma = options.smoothing_scale * L, edge = mean_edge_length(V, topology);
      if (edge > 0)
        curvature_options.smoothing_rounds =
            std::max(curvature_options.smoothing_rounds,
                     static_cast<int>(std::min(400.0, std::round(sigma * sigma / (0.43 * edge * edge)))));
    }
    curvature = principal_curvatures(V, F, topology, curvature_options);
    derivative = curvature_derivative(V, F, topology, *curvature);
  }
  const auto append = [&](std::vector<Polyline> more) {
    lines.insert(lines.end(), std::make_move_iterator(more.begin()), std::make_move_iterator(more.end()));
  };
  if (options.contours)
    append(occluding_contours(V, F, curvature ? curvature->N : vertex_normals(V, F, options.curvature.normal_weighting),
                              view));
  if (options.suggestive_contours)
    append(suggestive_contours(V, F, *curvature, derivative, view, options.suggestive_threshold / (L * L)));
  if (options.ridges || options.valleys)
    append(
        ridges_and_valleys(V, F, *curvature, derivative, options.ridge_threshold / L, options.ridges, options.valleys));
  return lines;
}

}  // namespace vertexflow
