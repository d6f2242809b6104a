// Pieces every `vertexflow` subcommand shares: reading with warnings, JSON conversion.
#pragma once

#include "vertexflow/distance.h"
#include "vertexflow/flow.h"
#include "vertexflow/io.h"
#include "vertexflow/manifold_split.h"
#include "vertexflow/mesh_info.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace vertexflow::cli {

/// Options every subcommand has.
struct GlobalOptions {
  bool quiet = false;
};

/// Reads a mesh and prints one warning line per cleanup count to stderr (unless quiet).
Mesh read_mesh_with_warnings(const std::filesystem::path& path, const GlobalOptions& global,
                             ReadReport* report = nullptr);

/// A file a subcommand writes.
struct OutputFile {
  std::filesystem::path path;  ///< empty: not requested, skipped
  bool mesh = false;           ///< a mesh: needs a mesh extension
  /// Whether --force lets it replace an input file. Only a mesh output may: a report never
  /// replaces a mesh.
  bool may_replace_input = false;
};

/// Checks every output of a subcommand before any work (before the inputs are read), so a bad
/// path fails at once and no command writes some of its outputs and then fails on another's
/// path. Each output must not be a directory, must have a mesh extension where a mesh is
/// written, must be none of `inputs` (empty paths are skipped) unless `force` and
/// may_replace_input, none of the other outputs, and its directory must accept a new file
/// (check_output_writable). Throws IoError naming the path.
void check_outputs(const std::vector<std::filesystem::path>& inputs, const std::vector<OutputFile>& outputs,
                   bool force);

/// The mesh file read_mesh_with_warnings read last (empty before any): std::bad_alloc names no
/// file, so main() takes this one for its one-line "out of memory" error.
const std::string& last_input_path();

/// Whether `message` starts with "PATH: " for a mesh file read so far: main() adds no prefix
/// then (enhance --reference reads the input, then the reference, and an error about the input
/// must not be prefixed with the reference).
bool names_an_input(std::string_view message);

/// Human-readable format name, e.g. "PLY (binary)".
std::string describe_format(const ReadReport& report);

nlohmann::json to_json(const MeshInfo& info);
nlohmann::json to_json(const QualityStats& stats);
nlohmann::json to_json(const SurfaceRepairs& repairs);

/// Prints (unless quiet) one warning line per kind of repair remesh or simplify made to `input`
/// or to their result (manifold_split.h).
void warn_about_repairs(const std::string& input, const SurfaceRepairs& repairs, const GlobalOptions& global);
nlohmann::json to_json(const ReadReport& report);
/// mean, rms, max (absolute), the same divided by `length_scale` (*_relative), and points.
nlohmann::json to_json(const DistanceStats& stats, double length_scale);

/// Registers the options of the flow that `enhance` and `batch` share: --lambda, --mu,
/// --iterations, --min-quality, --sliver-floor, --sliver-stiffness, --no-projection (into
/// `no_projection`; the caller sets flow.project_to_input from it), --fairness, --feature-angle
/// and --solver.
void add_flow_options(CLI::App* command, FlowOptions& flow, bool& no_projection);

/// Registers the subcommands (one function per command file).
void register_info_command(CLI::App& app, const GlobalOptions& global);
void register_curvature_command(CLI::App& app, const GlobalOptions& global);
void register_enhance_command(CLI::App& app, const GlobalOptions& global);
void register_simplify_command(CLI::App& app, const GlobalOptions& global);
void register_remesh_command(CLI::App& app, const GlobalOptions& global);
void register_render_command(CLI::App& app, const GlobalOptions& global);
void register_lines_command(CLI::App& app, const GlobalOptions& global);
void register_compare_lines_command(CLI::App& app, const GlobalOptions& global);
void register_report_command(CLI::App& app, const GlobalOptions& global);
void register_compare_command(CLI::App& app, const GlobalOptions& global);
void register_batch_command(CLI::App& app, const GlobalOptions& global);

}  // namespace vertexflow::cli
