// `vertexflow render IN OUT.png [--color ...] [--wireframe] [--view ...] [--size WxH]
// [--shading smooth|flat|exaggerated] [--exaggeration A --scales N --sigma S --weights K --light X,Y,Z]
// [--frame-from MESH | --frame BOX] [--before MESH] [--texture none|checker --checker-squares N]`:
// a headless picture of a mesh (render.h).
// --flat and --smooth are kept as aliases of --shading flat and --shading smooth.
// The colour range is printed on stdout (and drawn, labelled, in the image's colour bar).
#include "camera_options.h"
#include "cli_common.h"
#include "progress.h"

#include "vertexflow/render.h"

#include <fmt/format.h>

#include <algorithm>
#include <map>

namespace vertexflow::cli {
namespace {

struct RenderCommandOptions {
  std::string input;
  std::string output;
  std::string color = "none";
  std::string texture = "none";
  std::string before;
  CameraCliOptions camera;
  std::optional<double> color_limit;
  bool wireframe = false;
  bool flat = false;
  bool smooth = false;
  std::string shading;
  std::optional<double> exaggeration;
  std::optional<int> scales;
  std::optional<double> sigma;
  std::vector<double> weights;
  std::vector<double> light;
  bool no_color_bar = false;
  bool json = false;
  bool force = false;
  RenderOptions render;
};

}  // namespace

void register_render_command(CLI::App& app, const GlobalOptions& global) {
  auto o = std::make_shared<RenderCommandOptions>();
  CLI::App* command =
      app.add_subcommand("render", "Render a mesh to a PNG image on the CPU (no display or GPU needed)");
  command->add_option("IN", o->input, "Input mesh")->required();
  command->add_option("OUT", o->output, "Output image (.png)")->required();
  command
      ->add_option("--color", o->color,
                   "Colour by mean or Gaussian curvature (red positive, blue negative), triangle quality 2r/R "
                   "(red = poor) or displacement from --before (white 0 .. red large)")
      ->check(CLI::IsMember({"none", "mean", "gauss", "quality", "displacement"}));
  // Checked in the callback rather than by CLI11, whose messages take two lines.
  command->add_option("--texture", o->texture,
                      "none (default), or checker: a checkerboard laid on the mesh's texture coordinates (the first "
                      "texcoord channel, e.g. an OBJ's vt), dark and light grey over the shading and colour, so that "
                      "a texture that swims or stretches shows");
  auto* squares = command
                      ->add_option("--checker-squares", o->render.checker_squares,
                                   "--texture checker: squares per unit of texture coordinate (1..256, default 16)")
                      ->check(CLI::Range(1, 256));
  command->add_option("--before", o->before,
                      "The mesh before the flow (same vertices and order), for --color displacement");
  command->add_flag("--wireframe", o->wireframe, "Draw the edges on the surface");
  add_camera_options(command, o->camera);
  auto* flat = command->add_flag("--flat", o->flat, "One normal per face: every triangle visible");
  auto* smooth = command->add_flag("--smooth", o->smooth, "Interpolated vertex normals (default)");
  flat->excludes(smooth);
  command
      ->add_option("--shading", o->shading,
                   "smooth (interpolated vertex normals, default), flat (one normal per face) or exaggerated "
                   "(Rusinkiewicz et al. 2006: multi-scale shading that shows detail at every scale)")
      ->check(CLI::IsMember({"smooth", "flat", "exaggerated"}))
      ->excludes(flat)
      ->excludes(smooth);
  command
      ->add_option("--exaggeration", o->exaggeration,
                   "Exaggerated shading: contrast a of every scale's clamped term (default 10)")
      ->check(CLI::PositiveNumber);
  command
      ->add_option("--scales", o->scales,
                   "Exaggerated shading: number of detail scales, sigma doubling from one to the next (default 4)")
      ->check(CLI::Range(0, 8));
  command
      ->add_option("--sigma", o->sigma,
                   "Exaggerated shading: smoothing of the first detail scale in mean edge lengths (default 1)")
      ->check(CLI::PositiveNumber);
  command
      ->add_option("--weights", o->weights,
                   "Exaggerated shading: weights of the detail terms, finest first, then of the overall shape "
                   "(scales + 1 values; default 1 each and 2 for the shape)")
      ->delimiter(',');
  command
      ->add_option("--light", o->light,
                   "Exaggerated shading: direction towards the light in camera coordinates, x right, y up, z towards "
                   "the viewer (default -1,1,1: upper left, in front)")
      ->expected(3)
      ->delimiter(',');
  command
      ->add_option("--range", o->color_limit,
                   "Fixed colour limit L: [-L, L] for curvature, [0, L] for displacement (default: the "
                   "larger magnitude of the 5th and 95th percentiles); give before and after the same L")
      ->check(CLI::PositiveNumber);
  command->add_option("--samples", o->render.samples, "Anti-aliasing samples per pixel (1 = off, default 4)")
      ->check(CLI::Range(1, 16));
  command->add_flag("--no-colorbar", o->no_color_bar, "Leave out the colour bar and its labels");
  command->add_flag("--json", o->json, "Print the colour range, camera frame and timings as JSON on stdout");
  command->add_flag("--force", o->force, "Allow OUT to be one of the input files");
  command->callback([o, squares, &global] {
    if (lowercase_extension(o->output) != ".png") throw IoError(o->output + ": the output must be a .png file");
    check_outputs({o->input, o->before, o->camera.frame_from},
                  {{o->output, /*mesh=*/false, /*may_replace_input=*/true}}, o->force);
    RenderOptions options = o->render;
    apply_camera_options(o->camera, options, global);
    const std::map<std::string, RenderColor> colors = {{"none", RenderColor::None},
                                                       {"mean", RenderColor::Mean},
                                                       {"gauss", RenderColor::Gauss},
                                                       {"quality", RenderColor::Quality},
                                                       {"displacement", RenderColor::Displacement}};
    options.color = colors.at(o->color);
    if (o->texture != "none" && o->texture != "checker")
      throw std::invalid_argument("--texture " + o->texture + ": expected none or checker");
    if (options.checker_squares < 1 || options.checker_squares > 256)
      throw std::invalid_argument(fmt::format("--checker-squares {}: expected 1..256", options.checker_squares));
    options.texture = o->texture == "checker" ? RenderTexture::Checker : RenderTexture::None;
    if (squares->count() > 0 && options.texture != RenderTexture::Checker && !global.quiet)
      fmt::print(stderr, "vertexflow: warning: --checker-squares is only used with --texture checker\n");
    options.shading = o->flat || o->shading == "flat" ? RenderShading::Flat
                      : o->shading == "exaggerated"   ? RenderShading::Exaggerated
                                                      : RenderShading::Smooth;
    if (o->exaggeration) options.exaggerated.exaggeration = *o->exaggeration;
    if (o->scales) options.exaggerated.scales = *o->scales;
    if (o->sigma) options.exaggerated.sigma = *o->sigma;
    options.exaggerated.weights = o->weights;
    if (!o->light.empty()) options.exaggerated_light = {o->light[0], o->light[1], o->light[2]};
    const bool exaggerated_options =
        o->exaggeration || o->scales || o->sigma || !o->weights.empty() || !o->light.empty();
    if (exaggerated_options && options.shading != RenderShading::Exaggerated && !global.quiet)
      fmt::print(stderr,
                 "vertexflow: warning: --exaggeration, --scales, --sigma, --weights and --light are only used with "
                 "--shading exaggerated\n");
    options.wireframe = o->wireframe;
    options.color_bar = !o->no_color_bar;
    options.color_limit = o->color_limit;
    // What the options alone decide is checked before the mesh is read, so that the error names
    // the option and not the input file (render_mesh would check these too, after the read).
    if (options.shading == RenderShading::Exaggerated) {
      const std::size_t expected = static_cast<std::size_t>(options.exaggerated.scales) + 1;
      if (!o->weights.empty() && o->weights.size() != expected)
        throw std::invalid_argument(fmt::format("--weights: {} values given for {} scales; expected {} (scales + 1)",
                                                o->weights.size(), options.exaggerated.scales, expected));
      for (const double w : o->weights)
        if (w < 0) throw std::invalid_argument(fmt::format("--weights: {} is not in the allowed range (>= 0)", w));
      if (!o->weights.empty() && std::all_of(o->weights.begin(), o->weights.end(), [](double w) { return w == 0; }))
        throw std::invalid_argument("--weights: the weights sum to 0");
      if (!o->light.empty() && options.exaggerated_light.norm() == 0)
        throw std::invalid_argument("--light: 0,0,0 is not a direction");
    }
    if (options.color == RenderColor::Displacement && o->before.empty())
      throw std::invalid_argument("--color displacement needs --before MESH");

    // The progress line on a terminal (progress.h), phases without a share: rendering is fast
    // (97k faces shade in 0.1 s) but reading a large mesh is not.
    ProgressLine progress(global);
    progress.report_unknown("reading " + o->input);
    const Mesh mesh = read_mesh_with_warnings(o->input, global);
    if (options.color == RenderColor::Displacement) {
      progress.report_unknown("reading " + o->before);
      Mesh before = read_mesh_with_warnings(o->before, global);
      if (before.num_vertices() != mesh.num_vertices())
        throw IoError(fmt::format("{}: has {} vertices but {} has {}; displacement needs the same vertices", o->before,
                                  before.num_vertices(), o->input, mesh.num_vertices()));
      options.displacement_reference = std::move(before.V);
    } else if (!o->before.empty() && !global.quiet) {
      fmt::print(stderr, "vertexflow: warning: --before is only used with --color displacement\n");
    }

    RenderInfo info;
    Image image;
    try {
      progress.report_unknown("rendering");
      image = render_mesh(mesh, options, &info);
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error(o->input + ": " + e.what());
    }
    progress.report_unknown("writing " + o->output);
    write_png(o->output, image);
    progress.finish();
    if (o->json) {
      nlohmann::json out = {
          {"input", o->input},
          {"output", o->output},
          {"width", image.width},
          {"height", image.height},
          {"frame", box_json(info.frame)},
          {"seconds",
           {{"prepare", info.prepare_seconds}, {"draw", info.draw_seconds}, {"readback", info.readback_seconds}}}};
      if (options.color != RenderColor::None)
        out["color"] = {{"quantity", info.color_quantity}, {"min", info.color_min}, {"max", info.color_max}};
      fmt::print("{}\n", out.dump(2));
    } else if (options.color != RenderColor::None) {
      fmt::print("colour range ({}): [{:.6g}, {:.6g}]\n", info.color_quantity, info.color_min, info.color_max);
    }
  });
}

}  // namespace vertexflow::cli
