// `vertexflow remesh IN OUT (--target-vertices N | --edge-length L) [...]`: uniform isotropic
// remeshing (CGAL), e.g. the paper's down-sampled input of Fig. 1(b).
#include "cli_common.h"
#include "progress.h"

#include "vertexflow/quality.h"
#include "vertexflow/remesh.h"
#include "vertexflow/remesh_report_json.h"

#include <fmt/format.h>

#include <map>
#include <string>

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
  command
      ->add_option("--small-pieces", o->remesh.isotropic.small_pieces,
                   "Pieces too small to remesh (see --small-piece-edges): remove them, or keep them unchanged")
      ->transform(CLI::CheckedTransformer(
          std::map<std::string, SmallPieces>{{"remove", SmallPieces::remove}, {"keep", SmallPieces::keep}},
          CLI::ignore_case))
      ->default_str("remove");
  command
      ->add_option("--small-piece-edges", o->remesh.isotropic.small_piece_edges,
                   "A connected piece whose bounding-box diagonal is below this many target edges is too small to "
                   "remesh (0: remesh every piece)")
      ->check(CLI::Range(0.0, 1000.0))
      ->capture_default_str();
  command
      ->add_option("--short-loop-edges", o->remesh.isotropic.short_loop_edges,
                   "A boundary loop shorter than this many target edges is kept, not collapsed (0: resample every "
                   "loop)")
      ->check(CLI::Range(0.0, 1000.0))
      ->capture_default_str();
  command
      ->add_option("--fill-holes-below", o->remesh.isotropic.fill_hole_edges,
                   "Fill boundary loops shorter than this many target edges before remeshing (0: fill none)")
      ->check(CLI::Range(0.0, 1000.0))
      ->capture_default_str();
  command->add_flag("--json", o->json, "Print a summary as JSON on stdout");
  command->add_flag("--force", o->force, "Allow OUT to be the input file");
  command->callback([o, &global] {
    check_outputs({o->input}, {{o->output, /*mesh=*/true, /*may_replace_input=*/true}}, o->force);
    // The progress line on a terminal (progress.h); CGAL's runs are most of the time.
    ProgressLine progress(global);
    const std::vector<double> part = progress_bounds({3, 95, 2});
    report_progress("reading " + o->input, part[0], part[1]);
    const Mesh mesh = read_mesh_with_warnings(o->input, global);
    warn_attributes_dropped(o->input, mesh, "remesh", global);
    RemeshResult result;
    try {
      const ProgressPart remeshing("remeshing", part[1], part[2]);
      if (o->edge_length > 0) {
        result = remesh_to_edge_length(mesh.V, mesh.F, o->edge_length, o->remesh.isotropic);
      } else {
        result = remesh_to_vertex_count(mesh.V, mesh.F, o->remesh);
      }
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error(o->input + ": " + e.what());
    }
    const RemeshReport& r = result.report;
    const bool searched = o->edge_length == 0;
    const QualityStats& quality = r.quality.all;
    const RemeshCleanup& cleanup = r.cleanup;
    if (!global.quiet) {
      for (std::size_t i = 0; i < r.attempts.size(); ++i)
        fmt::print(stderr, "vertexflow: run {}: edge length {:.6g} -> {} vertices ({:.2f} s)\n", i + 1,
                   r.attempts[i].edge_length, r.attempts[i].vertices, r.attempts[i].seconds);
      fmt::print(stderr, "vertexflow: remeshed {} -> {} vertices, {} faces{}, edge length {:.6g}, {:.2f} s\n",
                 mesh.num_vertices(), result.mesh.num_vertices(), result.mesh.num_faces(),
                 searched ? fmt::format(" (target {})", o->remesh.target_vertices) : "", r.edge_length, r.seconds);
      fmt::print(stderr, "vertexflow: quality 2r/R: min {:.3f}, p5 {:.3f}, mean {:.3f}, {:.2f}% below 0.3\n",
                 quality.min, quality.p5, quality.mean, 100 * quality.fraction_below_0_3);
      if (r.quality.rim_faces > 0)
        fmt::print(stderr,
                   "vertexflow: below 0.3: {:.2f}% of {} interior faces, {:.2f}% of {} rim faces (a corner on one of "
                   "{} boundary loops)\n",
                   100 * r.quality.interior.fraction_below_0_3, r.quality.interior_faces,
                   100 * r.quality.rim.fraction_below_0_3, r.quality.rim_faces, r.quality.boundary_loops);
      if (searched && !r.within_tolerance)
        fmt::print(stderr, "vertexflow: warning: {}: {} vertices is outside the {}% tolerance after {} runs\n",
                   o->input, result.mesh.num_vertices(), 100 * o->remesh.tolerance, r.attempts.size());
    }
    warn_about_repairs(o->input, r.repairs, global);
    if (!global.quiet && cleanup.small_pieces > 0)
      fmt::print(stderr,
                 "vertexflow: warning: {}: {} pieces ({} faces) smaller than {:g} target edges across, too small to "
                 "remesh: {}\n",
                 o->input, cleanup.small_pieces, cleanup.small_piece_faces, o->remesh.isotropic.small_piece_edges,
                 cleanup.small_pieces_kept ? "kept unchanged" : "removed (--small-pieces keep keeps them)");
    if (!global.quiet && cleanup.short_loops > 0)
      fmt::print(stderr,
                 "vertexflow: {}: {} boundary loops shorter than {:g} target edges kept ({} of their vertices held)\n",
                 o->input, cleanup.short_loops, o->remesh.isotropic.short_loop_edges, cleanup.held_loop_vertices);
    if (!global.quiet && cleanup.filled_holes > 0)
      fmt::print(stderr, "vertexflow: {}: {} holes shorter than {:g} target edges filled\n", o->input,
                 cleanup.filled_holes, o->remesh.isotropic.fill_hole_edges);
    if (!global.quiet && cleanup.collapsed_short_edges + cleanup.flipped_cap_edges + cleanup.removed_cap_faces > 0)
      fmt::print(stderr,
                 "vertexflow: warning: {}: the result had {} edges shorter than 1e-4 target edges (collapsed) and "
                 "zero-area faces ({} flipped, {} removed at the boundary)\n",
                 o->input, cleanup.collapsed_short_edges, cleanup.flipped_cap_edges, cleanup.removed_cap_faces);
    report_progress("writing " + o->output, part[2], part[3]);
    write_mesh(o->output, result.mesh);
    progress.finish();
    if (o->json) {
      // The library's report (remesh_report_json.h, shared with Python) and the file names.
      nlohmann::json out = remesh_report_json(result, mesh.num_vertices(), o->remesh, searched);
      out["input"] = o->input;
      out["output"] = o->output;
      fmt::print("{}\n", out.dump(2));
    }
  });
}

}  // namespace vertexflow::cli
