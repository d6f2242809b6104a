// `vertexflow compare RESULT INPUT [--reference DENSE] [--json] [--samples N] [--seed S]`: every
// figure of docs/metrics.md for a result of the flow (compare.h), as a table or as JSON.
#include "cli_common.h"
#include "progress.h"

#include "vertexflow/compare.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cstdint>

namespace vertexflow::cli {
namespace {

struct CompareCommandOptions {
  std::string result;
  std::string input;
  std::string reference;
  bool json = false;
  Index samples = SamplingOptions{}.samples;
  std::uint64_t seed = SamplingOptions{}.seed;
};

const char* kNotApplicable = "result and input have different connectivity";

nlohmann::json mesh_json(const std::string& file, const Mesh& mesh) {
  return {{"file", file}, {"vertices", mesh.num_vertices()}, {"faces", mesh.num_faces()}};
}

nlohmann::json symmetric_json(const SymmetricDistance& d, double scale, const char* a_to_b, const char* b_to_a) {
  return {{a_to_b, distance_stats_json(d.a_to_b, scale)},
          {b_to_a, distance_stats_json(d.b_to_a, scale)},
          {"hausdorff", d.hausdorff},
          {"hausdorff_relative", d.hausdorff / scale}};
}

nlohmann::json edge_error_json(const EdgeErrorStats& s) {
  return {
      {"mean", s.mean}, {"max_over_mean", s.max_over_mean}, {"coefficient_of_variation", s.coefficient_of_variation}};
}

nlohmann::json percentiles_json(const MeanCurvaturePercentiles& h) {
  return {{"p5", h.p5}, {"p50", h.p50}, {"p95", h.p95}, {"p99", h.p99}};
}

nlohmann::json comparison_json(const MeshComparison& c, const CompareCommandOptions& o, const Mesh& result,
                               const Mesh& input, const Mesh* reference) {
  nlohmann::json j;
  j["result"] = mesh_json(o.result, result);
  j["input"] = mesh_json(o.input, input);
  j["reference"] = reference ? mesh_json(o.reference, *reference) : nlohmann::json(nullptr);
  j["samples"] = o.samples;
  j["seed"] = o.seed;
  j["length_scale"] = {{"diagonal", c.length_scale}, {"of", reference ? "reference" : "input"}};
  j["distance"]["result_input"] = symmetric_json(c.result_input, c.length_scale, "result_to_input", "input_to_result");
  j["distance"]["result_reference"] = c.result_reference ? symmetric_json(*c.result_reference, c.length_scale,
                                                                          "result_to_reference", "reference_to_result")
                                                         : nlohmann::json(nullptr);
  j["distance"]["input_reference"] =
      c.input_reference ? symmetric_json(*c.input_reference, c.length_scale, "input_to_reference", "reference_to_input")
                        : nlohmann::json(nullptr);
  j["curvature_surface"] = reference ? "reference" : "input";
  j["edge_error"] = {{"input", edge_error_json(c.edge_error_input)}, {"result", edge_error_json(c.edge_error_result)}};
  j["redistribution_rho"] = {{"input", c.redistribution_rho_input}, {"result", c.redistribution_rho_result}};
  j["abs_mean_curvature"] = {{"input", percentiles_json(c.abs_mean_curvature_input)},
                             {"result", percentiles_json(c.abs_mean_curvature_result)}};
  j["quality"] = {{"input", nlohmann::json(c.quality_input)}, {"result", nlohmann::json(c.quality_result)}};
  j["degenerate_faces"] = {{"input", c.degenerate_faces_input}, {"result", c.degenerate_faces_result}};
  j["flipped_faces"] = c.flipped_faces ? nlohmann::json{{"applicable", true}, {"count", *c.flipped_faces}}
                                       : nlohmann::json{{"applicable", false}, {"reason", kNotApplicable}};
  return j;
}

void print_table(const MeshComparison& c, const CompareCommandOptions& o, const Mesh& result, const Mesh& input,
                 const Mesh* reference) {
  auto mesh_line = [](const char* role, const std::string& file, const Mesh& mesh) {
    fmt::print("{:<11}{} ({} vertices, {} faces)\n", role, file, mesh.num_vertices(), mesh.num_faces());
  };
  mesh_line("result", o.result, result);
  mesh_line("input", o.input, input);
  if (reference) mesh_line("reference", o.reference, *reference);
  fmt::print("lengths in % of the {}'s bounding-box diagonal {:.6g} (absolute in parentheses); {} samples, seed {}\n\n",
             reference ? "reference" : "input", c.length_scale, o.samples, o.seed);

  const double scale = c.length_scale;
  auto length = [scale](double value) { return fmt::format("{:.4f}% ({:.3g})", 100.0 * value / scale, value); };
  fmt::print("{:<28}{:<26}{:<26}{}\n", "distance", "mean", "rms", "max");
  auto distance_line = [&](const std::string& what, const DistanceStats& s) {
    fmt::print("{:<28}{:<26}{:<26}{}\n", what, length(s.mean), length(s.rms), length(s.max));
  };
  distance_line("result -> input", c.result_input.a_to_b);
  distance_line("input -> result", c.result_input.b_to_a);
  fmt::print("{:<28}{}\n", "Hausdorff result, input", length(c.result_input.hausdorff));
  if (c.result_reference) {
    distance_line("result -> reference", c.result_reference->a_to_b);
    distance_line("reference -> result", c.result_reference->b_to_a);
    fmt::print("{:<28}{}\n", "Hausdorff result, reference", length(c.result_reference->hausdorff));
  }
  if (c.input_reference) {
    distance_line("input -> reference", c.input_reference->a_to_b);
    distance_line("reference -> input", c.input_reference->b_to_a);
    fmt::print("{:<28}{}\n", "Hausdorff input, reference", length(c.input_reference->hausdorff));
  }

  fmt::print("\n{:<36}{:<16}{}\n", "", "input", "result");
  auto row = [](const std::string& what, const std::string& in, const std::string& out) {
    fmt::print("{:<36}{:<16}{}\n", what, in, out);
  };
  auto number = [](double value) { return fmt::format("{:.4g}", value); };
  const std::string surface = reference ? "reference" : "input";
  row("edge error delta_e mean", number(c.edge_error_input.mean), number(c.edge_error_result.mean));
  row("edge error max/mean", number(c.edge_error_input.max_over_mean), number(c.edge_error_result.max_over_mean));
  row("edge error CV (std/mean)", number(c.edge_error_input.coefficient_of_variation),
      number(c.edge_error_result.coefficient_of_variation));
  row("redistribution rho", number(c.redistribution_rho_input), number(c.redistribution_rho_result));
  fmt::print("  (curvature of the {} surface at each vertex's closest point)\n", surface);
  const MeanCurvaturePercentiles* h[2] = {&c.abs_mean_curvature_input, &c.abs_mean_curvature_result};
  row("|H| p5", number(h[0]->p5), number(h[1]->p5));
  row("|H| p50", number(h[0]->p50), number(h[1]->p50));
  row("|H| p95", number(h[0]->p95), number(h[1]->p95));
  row("|H| p99", number(h[0]->p99), number(h[1]->p99));
  const QualityStats* q[2] = {&c.quality_input, &c.quality_result};
  row("quality 2r/R min", number(q[0]->min), number(q[1]->min));
  row("quality 2r/R mean", number(q[0]->mean), number(q[1]->mean));
  row("quality 2r/R p5", number(q[0]->p5), number(q[1]->p5));
  row("quality below 0.3", fmt::format("{:.2f}%", 100 * q[0]->fraction_below_0_3),
      fmt::format("{:.2f}%", 100 * q[1]->fraction_below_0_3));
  row("degenerate faces", std::to_string(c.degenerate_faces_input), std::to_string(c.degenerate_faces_result));
  row("flipped faces (input -> result)", "",
      c.flipped_faces ? std::to_string(*c.flipped_faces) : std::string("not applicable: ") + kNotApplicable);
  fmt::print("\nquality histogram (bins of 0.1 from 0 to 1)\n");
  fmt::print("  input   {}\n  result  {}\n", fmt::join(q[0]->histogram, " "), fmt::join(q[1]->histogram, " "));
}

}  // namespace

void register_compare_command(CLI::App& app, const GlobalOptions& global) {
  auto o = std::make_shared<CompareCommandOptions>();
  CLI::App* command = app.add_subcommand(
      "compare", "Measure a result of the flow against its input and a reference: distances, uniformity, quality");
  command->add_option("RESULT", o->result, "The flow's result (or any mesh to assess)")->required();
  command->add_option("INPUT", o->input, "The mesh the flow was given")->required();
  command->add_option("--reference", o->reference, "A dense mesh of the same surface (the ground truth)");
  command->add_flag("--json", o->json, "Print JSON instead of a table");
  command->add_option("--samples", o->samples, "Area-uniform samples per mesh, besides its vertices and edge midpoints")
      ->check(CLI::Range(0, 100000000))
      ->capture_default_str();
  command->add_option("--seed", o->seed, "Seed of the sampling")->capture_default_str();
  command->callback([o, &global] {
    // The progress line on a terminal (progress.h): reading, then the comparison (curvatures,
    // trees, queries), most of the time; the shares are rough.
    ProgressLine progress(global);
    const std::vector<double> part = progress_bounds({3, 3, o->reference.empty() ? 0.0 : 10.0, 100});
    report_progress("reading " + o->result, part[0], part[1]);
    const Mesh result = read_mesh_with_warnings(o->result, global);
    report_progress("reading " + o->input, part[1], part[2]);
    const Mesh input = read_mesh_with_warnings(o->input, global);
    Mesh reference;
    if (!o->reference.empty()) {
      report_progress("reading " + o->reference, part[2], part[3]);
      reference = read_mesh_with_warnings(o->reference, global);
    }
    const Mesh* reference_ptr = o->reference.empty() ? nullptr : &reference;
    CompareOptions options;
    options.sampling.samples = o->samples;
    options.sampling.seed = o->seed;
    MeshComparison c;
    try {
      report_progress("comparing", part[3], part[4]);
      c = compare_meshes(result, input, reference_ptr, options);
    } catch (const CompareError& e) {
      const std::string& file = e.role() == MeshRole::Result  ? o->result
                                : e.role() == MeshRole::Input ? o->input
                                                              : o->reference;
      throw std::runtime_error(file + ": " + e.what());
    }
    progress.finish();
    if (o->json) {
      fmt::print("{}\n", comparison_json(c, *o, result, input, reference_ptr).dump(2));
    } else {
      print_table(c, *o, result, input, reference_ptr);
    }
  });
}

}  // namespace vertexflow::cli
