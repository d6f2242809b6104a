// `vertexflow lines IN OUT.svg|OUT.png`: a line drawing (line_drawing.h) with render's camera;
// `vertexflow compare-lines COARSE DENSE`: line-drawing fidelity against a dense mesh.
#include "camera_options.h"
#include "cli_common.h"
#include "progress.h"

#include "vertexflow/line_drawing.h"

#include <fmt/format.h>

#include <cmath>
#include <set>

namespace vertexflow::cli {
namespace {

// The line options both commands share.
struct LineCliOptions {
  std::vector<std::string> types{"contours", "suggestive-contours", "ridges", "valleys"};
  LineOptions lines;
  double depth_tolerance = LineDrawingOptions{}.depth_tolerance_pixels;
  bool no_hidden_line_removal = false;
};

void add_line_options(CLI::App* command, LineCliOptions& o) {
  command->add_option("--lines", o.types, "Line types to draw (default: all)")
      ->delimiter(',')
      ->check(CLI::IsMember({"contours", "suggestive-contours", "ridges", "valleys"}));
  command
      ->add_option("--suggestive-threshold", o.lines.suggestive_threshold,
                   "Keep suggestive contours where tan(theta) D_w k_r >= T / L^2 (lines.h; default 20)")
      ->check(CLI::NonNegativeNumber);
  command
      ->add_option("--ridge-threshold", o.lines.ridge_threshold,
                   "Ridges need k1 >= T / L, valleys -k2 >= T / L (default 25)")
      ->check(CLI::NonNegativeNumber);
  command
      ->add_option("--smoothing-scale", o.lines.smoothing_scale,
                   "Smooth the curvature over sigma = S * L instead of one ring (lines.h; default: 0 = one ring for "
                   "lines, 0.01 for compare-lines)")
      ->check(CLI::NonNegativeNumber);
  command
      ->add_option("--length-scale", o.lines.length_scale,
                   "L of the thresholds in mesh units (default: the bounding-box diagonal)")
      ->check(CLI::NonNegativeNumber);
  command
      ->add_option("--depth-tolerance", o.depth_tolerance,
                   "Hidden-line test slack in pixels' worth of depth (default 2)")
      ->check(CLI::NonNegativeNumber);
  command->add_flag("--no-hidden-line-removal", o.no_hidden_line_removal, "Draw lines behind the surface too");
}

void apply_line_options(const LineCliOptions& o, LineDrawingOptions& drawing) {
  const std::set<std::string> types(o.types.begin(), o.types.end());
  drawing.lines = o.lines;
  drawing.lines.contours = types.count("contours") > 0;
  drawing.lines.suggestive_contours = types.count("suggestive-contours") > 0;
  drawing.lines.ridges = types.count("ridges") > 0;
  drawing.lines.valleys = types.count("valleys") > 0;
  drawing.hidden_line_removal = !o.no_hidden_line_removal;
  drawing.depth_tolerance_pixels = o.depth_tolerance;
}

struct LinesCommandOptions {
  std::string input, output;
  CameraCliOptions camera;
  LineCliOptions lines;
  double line_width = 1.5;
  bool shaded = false;
  bool json = false;
  bool force = false;
};

struct CompareLinesOptions {
  std::string coarse, dense;
  LineCliOptions lines;
  LineFidelityOptions fidelity;
  std::string size = "800x600";
  bool json = false;
};

}  // namespace

void register_lines_command(CLI::App& app, const GlobalOptions& global) {
  auto o = std::make_shared<LinesCommandOptions>();
  CLI::App* command = app.add_subcommand(
      "lines", "Draw contours, suggestive contours, ridges and valleys to SVG or PNG, hidden lines removed");
  command->add_option("IN", o->input, "Input mesh")->required();
  command->add_option("OUT", o->output, "Output drawing (.svg or .png)")->required();
  add_camera_options(command, o->camera);
  add_line_options(command, o->lines);
  command->add_option("--line-width", o->line_width, "Contour width in pixels (other lines 0.75 of it; default 1.5)")
      ->check(CLI::Range(0.1, 16.0));
  command->add_flag("--shaded", o->shaded, "PNG: draw the lines over the shaded surface (render's plain shading)");
  command->add_flag("--json", o->json, "Print the line counts, camera frame and timings as JSON on stdout");
  command->add_flag("--force", o->force, "Allow OUT to be one of the input files");
  command->callback([o, &global] {
    const std::string ext = lowercase_extension(o->output);
    if (ext != ".svg" && ext != ".png") throw IoError(o->output + ": the output must be a .svg or .png file");
    if (o->shaded && ext != ".png") throw std::invalid_argument("--shaded needs a .png output");
    check_outputs({o->input, o->camera.frame_from}, {{o->output, /*mesh=*/false, /*may_replace_input=*/true}},
                  o->force);
    LineDrawingOptions options;
    options.render.color_bar = false;
    apply_camera_options(o->camera, options.render, global);
    apply_line_options(o->lines, options);
    // The progress line on a terminal (progress.h), phases without a share.
    ProgressLine progress(global);
    progress.report_unknown("reading " + o->input);
    const Mesh mesh = read_mesh_with_warnings(o->input, global);
    progress.report_unknown("drawing lines");
    LineDrawing drawing;
    Image underlay;
    try {
      drawing = draw_lines(mesh, options);
      if (o->shaded) underlay = render_mesh(mesh, options.render);
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error(o->input + ": " + e.what());
    }
    if (ext == ".svg")
      write_svg(o->output, drawing, o->line_width);
    else
      write_png(o->output, line_image(drawing, o->line_width, underlay));
    progress.finish();
    if (o->json) {
      nlohmann::json counts;
      for (const LineType t : {LineType::Contour, LineType::SuggestiveContour, LineType::Ridge, LineType::Valley})
        counts[std::string(line_type_name(t))] = {{"extracted", drawing.extracted[static_cast<std::size_t>(t)]},
                                                  {"drawn", drawing.drawn[static_cast<std::size_t>(t)]}};
      fmt::print("{}\n", nlohmann::json{{"input", o->input},
                                        {"output", o->output},
                                        {"width", drawing.width},
                                        {"height", drawing.height},
                                        {"frame", box_json(drawing.camera.frame)},
                                        {"lines", counts},
                                        {"seconds",
                                         {{"lines", drawing.lines_seconds},
                                          {"depth", drawing.depth_seconds},
                                          {"visibility", drawing.visibility_seconds}}}}
                             .dump(2));
    }
  });
}

void register_compare_lines_command(CLI::App& app, const GlobalOptions& global) {
  auto o = std::make_shared<CompareLinesOptions>();
  CLI::App* command = app.add_subcommand(
      "compare-lines",
      "Line-drawing fidelity of COARSE against DENSE: precision, recall and F1 of line pixels within 2 px, "
      "averaged over views around the model");
  o->lines.lines.smoothing_scale = default_fidelity_drawing().lines.smoothing_scale;
  command->add_option("COARSE", o->coarse, "The mesh to judge")->required();
  command->add_option("DENSE", o->dense, "The dense (reference) mesh")->required();
  command->add_option("--views", o->fidelity.views, "Azimuths evenly spaced around +y (default 8)")
      ->check(CLI::Range(1, 360));
  command->add_option("--elevation", o->fidelity.elevation_degrees, "Degrees above the xz plane (default 15)")
      ->check(CLI::Range(-90.0, 90.0));
  command->add_option("--size", o->size, "Image size WxH per view (default 800x600)")->check(image_size_check());
  command->add_option("--match-pixels", o->fidelity.match_pixels, "Chamfer radius in pixels (default 2)")
      ->check(CLI::NonNegativeNumber);
  add_line_options(command, o->lines);
  command->add_flag("--json", o->json, "Print the result as JSON on stdout");
  command->callback([o, &global] {
    std::tie(o->fidelity.width, o->fidelity.height) = parse_image_size(o->size);
    apply_line_options(o->lines, o->fidelity.drawing);
    // The progress line on a terminal (progress.h), phases without a share.
    ProgressLine progress(global);
    progress.report_unknown("reading " + o->coarse);
    const Mesh coarse = read_mesh_with_warnings(o->coarse, global);
    progress.report_unknown("reading " + o->dense);
    const Mesh dense = read_mesh_with_warnings(o->dense, global);
    progress.report_unknown(fmt::format("drawing and matching {} views", o->fidelity.views));
    // Both are drawn in the dense mesh's frame: a coarse mesh elsewhere draws nothing there, and
    // its F1 of 0 says where it is, not how its lines compare.
    const BoundingBox coarse_box = bounding_box(coarse.V), dense_box = bounding_box(dense.V);
    if (((coarse_box.max.array() < dense_box.min.array()).any() ||
         (dense_box.max.array() < coarse_box.min.array()).any()) &&
        !global.quiet)
      fmt::print(stderr,
                 "vertexflow: warning: {} and {}: the bounding boxes do not overlap, so the drawings cannot match "
                 "(both are framed on {})\n",
                 o->coarse, o->dense, o->dense);
    LineFidelity fidelity;
    try {
      fidelity = line_drawing_fidelity(coarse, dense, o->fidelity);
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error(o->coarse + " against " + o->dense + ": " + e.what());
    }
    progress.finish();
    if (o->json) {
      nlohmann::json views = nlohmann::json::array();
      for (const LineFidelityView& v : fidelity.views)
        views.push_back({{"azimuth", v.azimuth_degrees},
                         {"precision", v.precision},
                         {"recall", v.recall},
                         {"f1", v.f1},
                         {"coarse_pixels", v.coarse_pixels},
                         {"dense_pixels", v.dense_pixels}});
      fmt::print("{}\n", nlohmann::json{{"coarse", o->coarse},
                                        {"dense", o->dense},
                                        {"match_pixels", o->fidelity.match_pixels},
                                        {"elevation", o->fidelity.elevation_degrees},
                                        {"width", o->fidelity.width},
                                        {"height", o->fidelity.height},
                                        {"precision", fidelity.precision},
                                        {"recall", fidelity.recall},
                                        {"f1", fidelity.f1},
                                        {"views", views}}
                             .dump(2));
      return;
    }
    // Undefined (NaN: neither drawing has a line pixel) reads "no lines" (JSON: null).
    const auto number = [](double x) { return std::isnan(x) ? std::string("-") : fmt::format("{:.3f}", x); };
    const auto f1 = [](double x) { return std::isnan(x) ? std::string("no lines") : fmt::format("{:.3f}", x); };
    fmt::print("{:>8} {:>10} {:>8} {:>8} {:>13} {:>12}\n", "azimuth", "precision", "recall", "F1", "coarse pixels",
               "dense pixels");
    for (const LineFidelityView& v : fidelity.views)
      fmt::print("{:>8.1f} {:>10} {:>8} {:>8} {:>13} {:>12}\n", v.azimuth_degrees, number(v.precision),
                 number(v.recall), f1(v.f1), v.coarse_pixels, v.dense_pixels);
    fmt::print("{:>8} {:>10} {:>8} {:>8}\n", "mean", number(fidelity.precision), number(fidelity.recall),
               f1(fidelity.f1));
  });
}

}  // namespace vertexflow::cli
