// `vertexflow curvature IN OUT [--color ...] [--smooth N] [--json]`: principal curvatures and
// directions per vertex, written as PLY properties (and optionally as colours).
#include "cli_common.h"
#include "progress.h"

#include "vertexflow/colormap.h"
#include "vertexflow/curvature.h"
#include "vertexflow/statistics.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <vector>

namespace vertexflow::cli {
namespace {

struct CurvatureCommandOptions {
  std::string input;
  std::string output;
  std::string color = "none";
  int smoothing_rounds = 0;
  bool json = false;
  bool force = false;
};

nlohmann::json summary(const Eigen::VectorXd& values) {
  const std::vector<double> sample(values.data(), values.data() + values.size());
  return {{"min", percentile(sample, 0)},    {"p5", percentile(sample, 5)},     {"median", percentile(sample, 50)},
          {"p95", percentile(sample, 95)},   {"max", percentile(sample, 100)},  {"mean", values.size() ? values.mean() : 0.0}};
}

}  // namespace

void register_curvature_command(CLI::App& app, const GlobalOptions& global) {
  auto o = std::make_shared<CurvatureCommandOptions>();
  CLI::App* command = app.add_subcommand(
      "curvature", "Estimate principal curvatures (Rusinkiewicz 2004) and write them as per-vertex PLY properties");
  command->add_option("IN", o->input, "Input mesh")->required();
  command->add_option("OUT", o->output, "Output mesh; PLY keeps k1 k2 H K T1x.. T2z as vertex properties")->required();
  command->add_option("--color", o->color, "Colour vertices by a quantity (diverging map, red positive)")
      ->check(CLI::IsMember({"none", "mean", "gauss", "k1", "k2", "abs"}));
  command->add_option("--smooth", o->smoothing_rounds, "Rounds of one-ring tensor smoothing (default 0)")
      ->check(CLI::Range(0, 100));
  command->add_flag("--json", o->json, "Print summary statistics as JSON on stdout");
  command->add_flag("--force", o->force, "Allow OUT to be the input file");
  command->callback([o, &global] {
    check_outputs({o->input}, {{o->output, /*mesh=*/true, /*may_replace_input=*/true}}, o->force);
    // The progress line on a terminal (progress.h); curvature at 1M vertices is about as long as
    // reading and writing the mesh together (docs/benchmarks.md).
    ProgressLine progress(global);
    const std::vector<double> part = progress_bounds({25, 50, 25});
    report_progress("reading " + o->input, part[0], part[1]);
    Mesh mesh = read_mesh_with_warnings(o->input, global);
    report_progress("curvature", part[1], part[2]);
    const Topology topology = build_topology(mesh.F, mesh.num_vertices());
    CurvatureOptions options;
    options.smoothing_rounds = o->smoothing_rounds;
    Curvature c;
    try {
      c = principal_curvatures(mesh.V, mesh.F, topology, options);
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error(o->input + ": " + e.what());
    }

    const std::map<std::string, Eigen::VectorXd> quantities = {
        {"k1", c.k1}, {"k2", c.k2}, {"mean", c.mean()}, {"gauss", c.gaussian()}, {"abs", c.absolute_sum()}};
    mesh.set_vertex_property("k1", c.k1);
    mesh.set_vertex_property("k2", c.k2);
    mesh.set_vertex_property("H", c.mean());
    mesh.set_vertex_property("K", c.gaussian());
    const char* axes = "xyz";
    for (int a = 0; a < 3; ++a) mesh.set_vertex_property(fmt::format("T1{}", axes[a]), c.T1.col(a));
    for (int a = 0; a < 3; ++a) mesh.set_vertex_property(fmt::format("T2{}", axes[a]), c.T2.col(a));
    double limit = 0;
    if (o->color != "none") {
      const Eigen::VectorXd& values = quantities.at(o->color);
      limit = robust_color_limit(values);
      mesh.set_vertex_colors(diverging_colors(values, limit));
      if (!global.quiet && !o->json)
        fmt::print(stderr, "vertexflow: colour range for {}: [{:.6g}, {:.6g}] (5th-95th percentile magnitude)\n",
                   o->color, o->color == "abs" ? 0.0 : -limit, limit);
    }
    if (format_from_path(o->output) != MeshFormat::Ply && !global.quiet)
      fmt::print(stderr, "vertexflow: warning: {}: only PLY stores per-vertex properties; writing geometry{}\n",
                 o->output, mesh.vertex_colors().rows() ? " and colours" : "");
    report_progress("writing " + o->output, part[2], part[3]);
    write_mesh(o->output, mesh);
    progress.finish();
    if (o->json) {
      nlohmann::json out;
      out["input"] = o->input;
      out["output"] = o->output;
      out["vertices"] = mesh.num_vertices();
      for (const auto& [name, values] : quantities) out[name] = summary(values);
      if (o->color != "none") out["color"] = {{"quantity", o->color}, {"min", o->color == "abs" ? 0.0 : -limit}, {"max", limit}};
      fmt::print("{}\n", out.dump(2));
    }
  });
}

}  // namespace vertexflow::cli
