// Pieces every `vertexflow` subcommand shares: reading with warnings, JSON conversion.
#pragma once

#include "vertexflow/distance.h"
#include "vertexflow/enhance_options.h"
#include "vertexflow/html_report.h"
#include "vertexflow/io.h"
#include "vertexflow/manifold_split.h"
#include "vertexflow/mesh_info.h"
#include "vertexflow/report_json.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <initializer_list>
#include <map>
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
                             ReadReport* report = nullptr, const ReadOptions& options = {});

/// Writes `mesh` to `path` (write_mesh), first printing one warning line naming what the
/// output's format cannot hold (attributes_not_written), unless quiet.
void write_mesh_with_warnings(const std::filesystem::path& path, const Mesh& mesh, const GlobalOptions& global);

/// One warning line, unless quiet, when `input` carries attributes a command that builds new
/// connectivity (`what`: "remesh", "simplify") does not carry.
void warn_attributes_dropped(const std::filesystem::path& input, const Mesh& mesh, const char* what,
                             const GlobalOptions& global);

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
nlohmann::json to_json(const SurfaceRepairs& repairs);

/// Prints (unless quiet) one warning line per kind of repair remesh or simplify made to `input`
/// or to their result (manifold_split.h).
void warn_about_repairs(const std::string& input, const SurfaceRepairs& repairs, const GlobalOptions& global);
nlohmann::json to_json(const ReadReport& report);

/// The enhance options given on a command line, by their Python names (enhance_options.h).
using GivenOptions = std::map<std::string, OptionValue, std::less<>>;

/// Registers one flag per option of enhance_options.h's table that has one (but those named in
/// `skip`), as `enhance` and `batch` share them: each value is checked against the table's
/// range as it is parsed (std::invalid_argument naming the flag) and stored in `given`.
void add_enhance_options(CLI::App* command, GivenOptions& given, std::initializer_list<std::string_view> skip = {});

/// Refuses NaN and infinities for every floating-point option of `app` and its subcommands (those
/// whose CLI11 type is FLOAT, lists included) before any other check of the option runs:
/// std::invalid_argument "--flag: VALUE is not a finite number", one line and exit 1 in main().
/// CLI11 parses "nan" and "inf" as numbers, and a NaN passes every range check (each comparison
/// is false), so without this a NaN angle gives a blank picture with exit 0. Options of
/// add_enhance_options are left to the option table's own check (in its words). Call it once,
/// after every command is registered.
void require_finite_numbers(CLI::App& app);

/// Words every numeric option's errors the same way, for `app` and its subcommands: a value that
/// is not a number of the option's kind is "--flag: 'abc' is not a number" (not an integer, ...),
/// and CLI11's range checks (CLI::Range, PositiveNumber, NonNegativeNumber) say "--flag: 100 is
/// not in the allowed range ([-90, 90])", as the enhance option table does, where CLI11 would
/// print its bounds with std::to_string (309 digits for an open range). Call it once, after
/// every command is registered.
void plain_option_messages(CLI::App& app);

/// EnhanceOptions with the given values set (the rest at their defaults).
EnhanceOptions enhance_options_from(const GivenOptions& given);

/// HTML report options whose title and labels name the two mesh files.
HtmlReportOptions html_report_options(const std::filesystem::path& input, const std::filesystem::path& result);

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
void register_lod_command(CLI::App& app, const GlobalOptions& global);

}  // namespace vertexflow::cli
