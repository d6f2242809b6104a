// Line drawings in an image (issue 17): lines.h's feature lines seen through render.h's camera,
// hidden lines removed with the renderer's depth buffer, written as SVG or drawn into a PNG;
// and the line-drawing fidelity of a coarse mesh against its dense mesh.
//
// Conventions
// - Camera: render.h's (orthographic, +y up, the frame filling 92% of the image minus the
//   legend strip); the lines are extracted for its viewing direction. Points are in pixels,
//   x from the left edge, y from the top edge (RenderCamera::project).
// - Hidden lines: each line is sampled every half pixel; a sample is visible when its depth is
//   at most the farthest surface depth among the 3 x 3 pixels around it plus
//   `depth_tolerance_pixels` pixels' worth of depth. The farthest of the 3 x 3 lets a contour,
//   where its own surface turns away at a grazing angle, see past it; the price is that a line
//   may show up to a pixel beyond the edge of a surface that hides it.
// - Styles: contours black at the line width, suggestive contours black at 0.75 of it, ridges
//   dark red (#a02818) and valleys dark blue (#1840a0) at 0.75 of it.
#pragma once

#include "vertexflow/lines.h"
#include "vertexflow/render.h"

#include <array>
#include <filesystem>
#include <string>
#include <vector>

namespace vertexflow {

struct LineDrawingOptions {
  /// Camera and image size (view, azimuth, elevation, width, height, frame); the shaded
  /// underlay of draw_line_image uses all of it.
  RenderOptions render;
  /// Which lines and their thresholds.
  LineOptions lines;
  /// Remove the parts of lines hidden by the surface (see above).
  bool hidden_line_removal = true;
  /// Depth slack of the visibility test in pixels' worth of mesh units.
  double depth_tolerance_pixels = 2.0;
};

/// One visible piece of a line, in pixels.
struct ImagePolyline {
  LineType type = LineType::Contour;
  std::vector<Eigen::Vector2d> points;
};

struct LineDrawing {
  int width = 0, height = 0;
  RenderCamera camera;
  std::vector<ImagePolyline> lines;  ///< visible pieces, in feature_lines' order
  /// Per LineType (by its value): 3D polylines extracted, and visible pieces drawn.
  std::array<int, 4> extracted{}, drawn{};
  /// Wall-clock seconds: feature lines (curvature included), depth buffer, visibility.
  double lines_seconds = 0, depth_seconds = 0, visibility_seconds = 0;
};

/// The visible feature lines of `mesh` in the image of `options.render`. Throws
/// std::invalid_argument for bad options (as render_mesh and feature_lines) and
/// std::runtime_error when OSMesa fails.
LineDrawing draw_lines(const Mesh& mesh, const LineDrawingOptions& options = {});

/// The drawing as an SVG document: a white background, then one <g id="..."> per line type
/// (line_type_name) with one <polyline> per piece, styled as above. `line_width` in pixels.
std::string svg_document(const LineDrawing& drawing, double line_width = 1.5);

/// The drawing as an image: anti-aliased strokes (cairo) over `underlay` (same size, e.g. a
/// render_mesh image) or over white when it is empty. Throws std::invalid_argument when the
/// underlay's size differs.
Image line_image(const LineDrawing& drawing, double line_width = 1.5, const Image& underlay = {});

/// Writes svg_document atomically (io.h's write_text_file). Throws IoError.
void write_svg(const std::filesystem::path& path, const LineDrawing& drawing, double line_width = 1.5);

/// The pixels a drawing's lines pass through (width * height, row-major from the top), every
/// type together: what line-drawing fidelity matches.
std::vector<char> line_pixels(const LineDrawing& drawing);

/// The line settings of line-drawing fidelity unless told otherwise: lines.h's defaults with the
/// curvature smoothed over 1% of L (LineOptions::smoothing_scale = 0.01), so that a coarse and
/// a dense mesh show features of the same size rather than each its own one-ring noise (on
/// bunny's 6k remesh against bunny.off this raises F1 from 0.58 to 0.78 and keeps the order of
/// the modes).
inline LineDrawingOptions default_fidelity_drawing() {
  LineDrawingOptions options;
  options.lines.smoothing_scale = 0.01;
  return options;
}

/// Line-drawing fidelity (our measure of the paper's Fig. 11 claim): `coarse` and `dense` drawn
/// with the same camera (the dense mesh's bounding box as the frame) and the same line options
/// (the length scale L set to the dense mesh's bounding-box diagonal for both), from `views`
/// azimuths evenly spaced around +y at `elevation_degrees`. Per view, precision is the share of
/// the coarse drawing's line pixels within `match_pixels` of a dense line pixel, recall the
/// share of the dense drawing's line pixels within `match_pixels` of a coarse one, and F1
/// their harmonic mean (0 when both are 0); a view where one drawing has no line pixel counts
/// precision or recall as 0. A view where neither has one has no precision, recall or F1 (NaN:
/// undefined, e.g. a flat mesh against itself) and is left out of the means, which are NaN when
/// no view has lines.
struct LineFidelityOptions {
  int views = 8;                  ///< >= 1
  double elevation_degrees = 15;  ///< in [-90, 90]
  int width = 800, height = 600;  ///< per view, in [16, 8192]
  double match_pixels = 2;        ///< chamfer radius, >= 0
  LineDrawingOptions drawing;     ///< lines and hidden-line settings (its render's view and size are set per view)
};

struct LineFidelityView {
  double azimuth_degrees = 0;
  double precision = 0, recall = 0, f1 = 0;  ///< NaN when neither drawing has a line pixel
  Index coarse_pixels = 0, dense_pixels = 0;
};

struct LineFidelity {
  std::vector<LineFidelityView> views;
  double precision = 0, recall = 0, f1 = 0;  ///< means over the views with lines (NaN: none has)
};

/// Throws std::invalid_argument for options out of range or an empty mesh.
LineFidelity line_drawing_fidelity(const Mesh& coarse, const Mesh& dense, const LineFidelityOptions& options = {});

}  // namespace vertexflow
