// `vertexflow report INPUT RESULT OUT.html [--json-report FILE]`: the HTML report of an enhance
// result that already exists (for example from an earlier `vertexflow enhance`).
#include "cli_common.h"
#include "progress.h"

#include "vertexflow/compare.h"
#include "vertexflow/enhance.h"
#include "vertexflow/html_report.h"

#include <fmt/format.h>

#include <stdexcept>

namespace vertexflow::cli {
namespace {

struct ReportOptions {
  std::string input;
  std::string result;
  std::string html_file;
  std::string json_file;
  Index max_display_faces = HtmlReportOptions{}.max_display_faces;
};

}  // namespace

void register_report_command(CLI::App& app, const GlobalOptions& global) {
  auto o = std::make_shared<ReportOptions>();
  CLI::App* command = app.add_subcommand(
      "report", "Write an HTML report (3D views, colour maps, quality histograms, metrics) of a result and its input");
  command->add_option("INPUT", o->input, "The mesh given to `vertexflow enhance`")->required();
  command
      ->add_option("RESULT", o->result,
                   "Its result: the input's vertices moved, with the input's faces or, after --edge-flips, its own")
      ->required();
  command->add_option("OUT", o->html_file, "The HTML file to write (self-contained, works offline)")->required();
  command->add_option("--json-report", o->json_file, "Also write the metrics as JSON to this file");
  command
      ->add_option("--max-display-faces", o->max_display_faces,
                   "Show meshes with more faces decimated (vertex clustering) in the 3D views")
      ->check(CLI::Range(1, 2'000'000'000))
      ->capture_default_str();
  command->callback([o, &global] {
    // Reports never replace a mesh: there is no --force here.
    check_outputs({o->input, o->result}, {{o->html_file}, {o->json_file}}, /*force=*/false);
    // The progress line on a terminal (progress.h): reading, the metrics (most of the time, as
    // in enhance --report), the HTML (its share a guess).
    ProgressLine progress(global);
    const std::vector<double> part = progress_bounds({3.5, 3.5, 80, 13});
    report_progress("reading " + o->input, part[0], part[1]);
    const Mesh input = read_mesh_with_warnings(o->input, global);
    report_progress("reading " + o->result, part[1], part[2]);
    const Mesh result = read_mesh_with_warnings(o->result, global);
    // Edge flips give a result faces of its own, but never another vertex or face count.
    if (result.num_vertices() != input.num_vertices() || result.num_faces() != input.num_faces())
      throw std::runtime_error(fmt::format(
          "{}: not a result of {} ({} vertices, {} faces here, {} vertices, {} faces there): a report compares an "
          "enhance result with its own input",
          o->result, o->input, result.num_vertices(), result.num_faces(), input.num_vertices(), input.num_faces()));
    // Each mesh's curvature, computed once for the metrics and the HTML report.
    nlohmann::json metrics;
    EnhanceCurvatures curvatures;
    try {
      const ProgressPart measuring("metrics", part[2], part[3]);
      metrics = enhance_metrics(input, result, nullptr, &curvatures);
    } catch (const CompareError& e) {
      throw std::runtime_error((e.role() == MeshRole::Result ? o->result : o->input) + ": " + e.what());
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error(o->input + ": " + e.what());
    }
    metrics["input"] = o->input;
    metrics["output"] = o->result;
    // File names need not be UTF-8: dump with U+FFFD for invalid bytes instead of failing.
    const auto replace = nlohmann::json::error_handler_t::replace;
    if (!o->json_file.empty()) write_text_file(o->json_file, metrics.dump(2, ' ', false, replace) + "\n");
    report_progress("HTML report", part[3], part[4]);
    HtmlReportOptions options = html_report_options(o->input, o->result);
    options.max_display_faces = o->max_display_faces;
    write_html_report(o->html_file, input, result, curvatures.input, curvatures.result,
                      metrics.dump(-1, ' ', false, replace), options);
    if (!global.quiet) fmt::print(stderr, "vertexflow: HTML report written to {}\n", o->html_file);
  });
}

}  // namespace vertexflow::cli
