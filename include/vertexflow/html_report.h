// HTML report: one self-contained page comparing an input mesh with the flow's result.
//
// The page holds two synchronised interactive 3D views (input, result: orbit, pan and zoom
// move both), a wireframe toggle, colour maps (mean curvature H, triangle quality 2r/R per
// face, displacement |result - input| per vertex), the quality histograms of the paper's
// Fig. 5 (10 bins of 2r/R over [0, 1], input vs result) and a table of metrics.
//
// Self-contained: the viewer (three.js, bundled from npm with esbuild when vertexflow is built)
// and the data are inside the file; it works offline from file:// and loads nothing. Mesh
// data is base64 of little-endian typed arrays: float32 positions relative to the input's
// bounding-box centre and uint32 triangle indices (stored once when the two meshes share them;
// a result with faces of its own, from edge flips, has its own indices too).
// The bytes depend only on the arguments (no time stamps), so identical input gives an
// identical file.
//
// Colours (computed here, not in the browser):
// - Mean curvature H = (k1 + k2) / 2 (curvature.h) of each mesh, diverging map (colormap.h)
//   red positive, blue negative; one range for both views, robust_color_limit of the input's H.
// - Quality: per face of each mesh's own faces, 2r/R = 0 red, 0.5 white, 1 blue (the diverging
//   map of 0.5 - q).
// - Displacement: |result - input| per vertex, white (0) to red (robust_color_limit of all).
//
// Large meshes: above `max_display_faces` faces the views show a vertex-clustering
// decimation (one clustering of the input's vertices, applied to both meshes so they keep
// shared vertices and the displacement map still matches; each mesh's faces are mapped
// through it, those that collapse dropped, at most max_display_faces of each), and the page
// says so. A merged vertex shows the mean position and mean H / displacement of its vertices,
// a kept face the mean quality of the faces merged into it. Histograms and metrics describe
// the full meshes.
#pragma once

#include "vertexflow/curvature.h"
#include "vertexflow/mesh.h"

#include <filesystem>
#include <string>
#include <string_view>

namespace vertexflow {

struct HtmlReportOptions {
  /// Page title (shown as heading and window title).
  std::string title = "vertexflow report";
  /// Names of the two meshes on the page, e.g. their file names.
  std::string input_label = "input";
  std::string result_label = "result";
  /// Meshes with more faces than this are decimated for display (see above). At least 1.
  Index max_display_faces = 1'000'000;
};

/// The report page as one string (UTF-8 HTML).
///
/// `result` must have the input's vertex and face counts: the input's faces, as vertex_flow
/// returns, or faces of its own over the same vertices, as edge flips give (edge_flips.h); its
/// view, quality colours, histogram and curvature then use its own faces, and displacement
/// stays per vertex. `metrics_json` is a JSON object shown as the metrics table (nested
/// objects become dotted names; {"input": a, "result": b} pairs and NAME_input / NAME_result
/// keys become one row with two columns), e.g. the JSON of `vertexflow enhance --report`;
/// an empty string gives an empty table. When both meshes have texture coordinates (the first
/// TexCoord channel, attributes.h), the page also has a checker-texture view of each, as
/// `render --texture checker` draws it. Throws std::invalid_argument when the vertex or face
/// counts differ, a result face has a corner that is not a vertex, a mesh is not manifold
/// (curvature.h), or metrics_json is not a JSON object.
std::string html_report(const Mesh& input, const Mesh& result, std::string_view metrics_json,
                        const HtmlReportOptions& options = {});

/// The same with each mesh's curvature computed by the caller, who needs it too (`vertexflow
/// enhance` measures both meshes with compare.h): principal_curvatures of each mesh on its own
/// faces with the default CurvatureOptions, as the overload above computes it; the page uses
/// its mean curvature. The same bytes as the overload above. Throws as above (but for a
/// non-manifold mesh, which has no curvature), and std::invalid_argument for a curvature
/// without one entry per vertex.
std::string html_report(const Mesh& input, const Mesh& result, const Curvature& input_curvature,
                        const Curvature& result_curvature, std::string_view metrics_json,
                        const HtmlReportOptions& options = {});

/// html_report written to `path` atomically (write_text_file in io.h). Throws as html_report,
/// and IoError when the file cannot be written.
void write_html_report(const std::filesystem::path& path, const Mesh& input, const Mesh& result,
                       std::string_view metrics_json, const HtmlReportOptions& options = {});

/// The same with the meshes' curvature given, as html_report above.
void write_html_report(const std::filesystem::path& path, const Mesh& input, const Mesh& result,
                       const Curvature& input_curvature, const Curvature& result_curvature,
                       std::string_view metrics_json, const HtmlReportOptions& options = {});

}  // namespace vertexflow
