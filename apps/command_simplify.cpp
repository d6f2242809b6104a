// `vertexflow simplify IN OUT (--faces N | --ratio R) [--free-boundary] [--json]`: quadric-error
// edge-collapse simplification (Garland and Heckbert 1997, through CGAL).
#include "cli_common.h"
#include "progress.h"

#include "vertexflow/quality.h"
#include "vertexflow/simplify.h"

#include <fmt/format.h>

namespace vertexflow::cli {
namespace {

struct SimplifyCommandOptions {
  std::string input;
  std::string output;
  SimplifyOptions simplify;
  bool free_boundary = false;
  bool json = false;
  bool force = false;
};

}  // namespace

void register_simplify_command(CLI::App& app, const GlobalOptions& global) {
  auto o = std::make_shared<SimplifyCommandOptions>();
  CLI::App* command =
      app.add_subcommand("simplify", "Simplify by quadric-error edge collapse (Garland-Heckbert), boundaries kept");
  command->add_option("IN", o->input, "Input mesh (a non-manifold one is split where it is not a disc)")->required();
  command->add_option("OUT", o->output, "Output mesh")->required();
  CLI::Option_group* budget = command->add_option_group("face budget", "Exactly one of");
  budget->add_option("--faces", o->simplify.target_faces, "Faces wanted (the result has N or N + 1)")
      ->check(CLI::PositiveNumber);
  budget->add_option("--ratio", o->simplify.target_ratio, "Faces wanted as a fraction of the input's, in (0, 1]")
      ->check(CLI::Range(0.0, 1.0));
  budget->require_option(1);
  command->add_flag("--free-boundary", o->free_boundary, "Let boundary edges collapse and boundary vertices move");
  command
      ->add_option("--method", o->simplify.method,
                   "cgal: CGAL's edge collapse (default); native: vertexflow's own, area-weighted quadrics, "
                   "about three times faster")
      ->transform(CLI::CheckedTransformer(simplify_method_names(), CLI::ignore_case))
      ->default_str("cgal");
  command->add_flag("--json", o->json, "Print a summary as JSON on stdout");
  command->add_flag("--force", o->force, "Allow OUT to be the input file");
  command->callback([o, &global] {
    check_outputs({o->input}, {{o->output, /*mesh=*/true, /*may_replace_input=*/true}}, o->force);
    // The progress line on a terminal (progress.h); CGAL's collapses are most of the time.
    ProgressLine progress(global);
    const std::vector<double> part = progress_bounds({5, 90, 5});
    report_progress("reading " + o->input, part[0], part[1]);
    const Mesh mesh = read_mesh_with_warnings(o->input, global);
    warn_attributes_dropped(o->input, mesh, "simplify", global);
    o->simplify.keep_boundary = !o->free_boundary;
    SimplifyResult result;
    try {
      report_progress("simplifying", part[1], part[2]);
      result = simplify(mesh.V, mesh.F, o->simplify);
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error(o->input + ": " + e.what());
    }
    const SimplifyReport& r = result.report;
    const QualityStats quality = summarize_quality(triangle_quality(result.mesh.V, result.mesh.F));
    if (!global.quiet) {
      fmt::print(stderr, "vertexflow: simplified {} -> {} faces (target {}), {} vertices, {:.3f} s\n", r.input_faces,
                 r.output_faces, r.target_faces, result.mesh.num_vertices(), r.seconds);
      fmt::print(stderr, "vertexflow: quality 2r/R: min {:.3f}, mean {:.3f}, {:.1f}% below 0.3\n", quality.min,
                 quality.mean, 100 * quality.fraction_below_0_3);
      if (!r.reached_target)
        fmt::print(stderr, "vertexflow: warning: {}: no further edge could be collapsed; {} faces remain\n", o->input,
                   r.output_faces);
    }
    warn_about_repairs(o->input, r.repairs, global);
    report_progress("writing " + o->output, part[2], part[3]);
    write_mesh(o->output, result.mesh);
    progress.finish();
    if (o->json) {
      nlohmann::json out;
      out["input"] = o->input;
      out["output"] = o->output;
      out["input_faces"] = r.input_faces;
      out["target_faces"] = r.target_faces;
      out["faces"] = r.output_faces;
      out["vertices"] = result.mesh.num_vertices();
      out["collapses"] = r.collapses;
      out["reached_target"] = r.reached_target;
      out["keep_boundary"] = o->simplify.keep_boundary;
      out["method"] = simplify_method_name(o->simplify.method);
      out["seconds"] = r.seconds;
      out["quality"] = nlohmann::json(quality);
      out["repairs"] = to_json(r.repairs);
      fmt::print("{}\n", out.dump(2));
    }
  });
}

}  // namespace vertexflow::cli
