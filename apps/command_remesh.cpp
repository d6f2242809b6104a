// `vertexflow remesh IN OUT (--target-vertices N | --edge-length L) [...]`: uniform isotropic
// remeshing (CGAL), e.g. the paper's down-sampled input of Fig. 1(b).
#include "cli_common.h"

#include "vertexflow/quality.h"
#include "vertexflow/remesh.h"

#include <fmt/format.h>

#include <chrono>

namespace vertexflow::cli {
namespace {

struct RemeshCommandOptions {
  std::string input;
  std::string output;
  RemeshOptions remesh;
  double edge_length = 0;
  bool json = false;
  bool force = false;
};

}  // namespace

void register_remesh_command(CLI::App& app, const GlobalOptions& global) {
  auto o = std::make_shared<RemeshCommandOptions>();
  CLI::App* command = app.add_subcommand(
      "remesh", "Uniform isotropic remeshing onto the input surface (CGAL), to a vertex count or an edge length");
  command->add_option("IN", o->input, "Input mesh (a non-manifold one is split where it is not a disc)")->required();
  command->add_option("OUT", o->output, "Output mesh")->required();
  CLI::Option_group* size = command->add_option_group("size", "Exactly one of");
  size->add_option("--target-vertices", o->remesh.target_vertices,
                   "Vertices wanted; the edge length is searched until the count is within the tolerance")
      ->check(CLI::Range(3, 1 << 30));
  size->add_option("--edge-length", o->edge_length, "Target edge length in input units (one run, no search)")
      ->check(CLI::PositiveNumber);
  size->require_option(1);
  command->add_option("--tolerance", o->remesh.tolerance, "Accepted relative deviation from --target-vertices")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  command->add_option("--max-attempts", o->remesh.max_attempts, "Remeshing runs at most in the search")
      ->check(CLI::Range(1, 20))
      ->capture_default_str();
  command->add_option("--iterations", o->remesh.isotropic.iterations, "CGAL remeshing rounds per run")
      ->check(CLI::Range(1, 100))
      ->capture_default_str();
  command->add_flag("--protect-boundary", o->remesh.isotropic.protect_boundary,
                    "Keep boundary edges exactly as in the input (default: resample them along the boundary)");
  command->add_flag("--json", o->json, "Print a summary as JSON on stdout");
  command->add_flag("--force", o->force, "Allow OUT to be the input file");
  command->callback([o, &global] {
    check_outputs({o->input}, {{o->output, /*mesh=*/true, /*may_replace_input=*/true}}, o->force);
    const Mesh mesh = read_mesh_with_warnings(o->input, global);
    warn_attributes_dropped(o->input, mesh, "remesh", global);
    RemeshResult result;
    try {
      if (o->edge_length > 0) {
        const auto start = std::chrono::steady_clock::now();
        result.mesh = remesh_isotropic(mesh.V, mesh.F, o->edge_length, o->remesh.isotropic, &result.report.repairs);
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        result.report.attempts.push_back({o->edge_length, result.mesh.num_vertices(), seconds});
        result.report.edge_length = o->edge_length;
        result.report.seconds = seconds;
      } else {
        result = remesh_to_vertex_count(mesh.V, mesh.F, o->remesh);
      }
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error(o->input + ": " + e.what());
    }
    const RemeshReport& r = result.report;
    const bool searched = o->edge_length == 0;
    const QualityStats quality = summarize_quality(triangle_quality(result.mesh.V, result.mesh.F));
    if (!global.quiet) {
      for (std::size_t i = 0; i < r.attempts.size(); ++i)
        fmt::print(stderr, "vertexflow: run {}: edge length {:.6g} -> {} vertices ({:.2f} s)\n", i + 1,
                   r.attempts[i].edge_length, r.attempts[i].vertices, r.attempts[i].seconds);
      fmt::print(stderr, "vertexflow: remeshed {} -> {} vertices, {} faces{}, edge length {:.6g}, {:.2f} s\n",
                 mesh.num_vertices(), result.mesh.num_vertices(), result.mesh.num_faces(),
                 searched ? fmt::format(" (target {})", o->remesh.target_vertices) : "", r.edge_length, r.seconds);
      fmt::print(stderr, "vertexflow: quality 2r/R: min {:.3f}, p5 {:.3f}, mean {:.3f}, {:.2f}% below 0.3\n",
                 quality.min, quality.p5, quality.mean, 100 * quality.fraction_below_0_3);
      if (searched && !r.within_tolerance)
        fmt::print(stderr, "vertexflow: warning: {}: {} vertices is outside the {}% tolerance after {} runs\n",
                   o->input, result.mesh.num_vertices(), 100 * o->remesh.tolerance, r.attempts.size());
    }
    warn_about_repairs(o->input, r.repairs, global);
    write_mesh(o->output, result.mesh);
    if (o->json) {
      nlohmann::json out;
      out["input"] = o->input;
      out["output"] = o->output;
      out["input_vertices"] = mesh.num_vertices();
      out["vertices"] = result.mesh.num_vertices();
      out["faces"] = result.mesh.num_faces();
      if (searched) {
        out["target_vertices"] = o->remesh.target_vertices;
        out["tolerance"] = o->remesh.tolerance;
        out["within_tolerance"] = r.within_tolerance;
      }
      out["edge_length"] = r.edge_length;
      out["runs"] = nlohmann::json::array();
      for (const RemeshAttempt& a : r.attempts)
        out["runs"].push_back({{"edge_length", a.edge_length}, {"vertices", a.vertices}, {"seconds", a.seconds}});
      out["iterations"] = o->remesh.isotropic.iterations;
      out["protect_boundary"] = o->remesh.isotropic.protect_boundary;
      out["seconds"] = r.seconds;
      out["quality"] = nlohmann::json(quality);
      out["repairs"] = to_json(r.repairs);
      fmt::print("{}\n", out.dump(2));
    }
  });
}

}  // namespace vertexflow::cli
