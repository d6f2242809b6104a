#include "cli_common.h"

#include "vertexflow/remesh_report_json.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <regex>
#include <set>
#include <stdexcept>
#include <system_error>

namespace vertexflow::cli {
namespace {

// Whether two paths name the same file, existing or not: weakly_canonical resolves the parts
// that exist (symbolic links, "..") and normalises the rest, so "out.ply" and "./x/../out.ply"
// match before either exists; equivalent() also catches hard links.
bool same_file(const std::filesystem::path& a, const std::filesystem::path& b) {
  std::error_code ec_a, ec_b, ec;
  const std::filesystem::path ca = std::filesystem::weakly_canonical(a, ec_a);
  const std::filesystem::path cb = std::filesystem::weakly_canonical(b, ec_b);
  const bool same_name = ec_a || ec_b ? a.lexically_normal() == b.lexically_normal() : ca == cb;
  return same_name || (std::filesystem::exists(a, ec) && std::filesystem::equivalent(a, b, ec));
}

}  // namespace

void check_outputs(const std::vector<std::filesystem::path>& inputs, const std::vector<OutputFile>& outputs,
                   bool force) {
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    const OutputFile& output = outputs[i];
    if (output.path.empty()) continue;
    std::error_code ec;
    if (std::filesystem::is_directory(output.path, ec))
      throw IoError(output.path.string() + ": is a directory, not an output file");
    if (output.mesh) format_from_path(output.path);
    for (const auto& input : inputs) {
      if (!input.empty()) check_output_path(input, output.path, force && output.may_replace_input, output.mesh);
    }
    for (std::size_t j = 0; j < i; ++j) {
      if (!outputs[j].path.empty() && same_file(output.path, outputs[j].path))
        throw IoError(output.path.string() + ": would overwrite another output of the same command (" +
                      outputs[j].path.string() + ")");
    }
  }
  // Only once the paths are known to be distinct and safe: the probes touch the file system.
  for (const OutputFile& output : outputs) {
    if (!output.path.empty()) check_output_writable(output.path);
  }
}

namespace {
// Every mesh file read so far, in order.
std::vector<std::string>& inputs_read() {
  static std::vector<std::string> paths;
  return paths;
}
}  // namespace

const std::string& last_input_path() {
  static const std::string none;
  return inputs_read().empty() ? none : inputs_read().back();
}

bool names_an_input(std::string_view message) {
  for (const std::string& path : inputs_read()) {
    if (message.size() > path.size() + 1 && message.substr(0, path.size()) == path &&
        message.substr(path.size(), 2) == ": ")
      return true;
  }
  return false;
}

Mesh read_mesh_with_warnings(const std::filesystem::path& path, const GlobalOptions& global, ReadReport* report,
                             const ReadOptions& options) {
  inputs_read().push_back(path.string());
  ReadReport local;
  ReadReport& r = report ? *report : local;
  Mesh mesh = read_mesh(path, &r, options);
  if (!global.quiet) {
    for (const std::string& warning : r.warnings())
      fmt::print(stderr, "vertexflow: warning: {}: {}\n", path.string(), warning);
  }
  return mesh;
}

void write_mesh_with_warnings(const std::filesystem::path& path, const Mesh& mesh, const GlobalOptions& global) {
  const std::string lost = attributes_not_written_warning(mesh, format_from_path(path));
  if (!lost.empty() && !global.quiet) fmt::print(stderr, "vertexflow: warning: {}: {}\n", path.string(), lost);
  write_mesh(path, mesh);
}

void warn_attributes_dropped(const std::filesystem::path& input, const Mesh& mesh, const char* what,
                             const GlobalOptions& global) {
  std::vector<std::string> names;
  for (const AttributeChannel& c : mesh.attributes.vertex) names.push_back("vertex " + c.name);
  for (const CornerChannel& c : mesh.attributes.corner) names.push_back("corner " + c.channel.name);
  for (const AttributeChannel& c : mesh.attributes.face) names.push_back("face " + c.name);
  if (!names.empty() && !global.quiet)
    fmt::print(stderr,
               "vertexflow: warning: {}: {} builds new faces and vertices and does not carry the input's attributes: "
               "{} (enhance keeps them)\n",
               input.string(), what, fmt::join(names, ", "));
}

std::string describe_format(const ReadReport& report) {
  std::string s = format_name(report.format);
  if (report.format != MeshFormat::Obj) s += report.binary ? " (binary)" : " (ASCII)";
  if (report.gzip) s += ", gzip";
  return s;
}

nlohmann::json to_json(const SurfaceRepairs& repairs) {
  return surface_repairs_json(repairs);
}

void warn_about_repairs(const std::string& input, const SurfaceRepairs& repairs, const GlobalOptions& global) {
  if (global.quiet) return;
  const ManifoldSplitCounts& split = repairs.input_split;
  if (split.any())
    fmt::print(stderr,
               "vertexflow: warning: {}: the mesh is not manifold or not consistently oriented: {} vertices split "
               "into one copy per fan, {} faces reoriented, {} edges treated as boundaries\n",
               input, split.held_vertices, split.reversed_faces, split.cut_edges);
  if (repairs.removed_degenerate_faces + repairs.duplicated_vertices > 0)
    fmt::print(stderr,
               "vertexflow: warning: {}: the result had {} zero-area faces (removed) and {} vertices pinched between "
               "fans (duplicated)\n",
               input, repairs.removed_degenerate_faces, repairs.duplicated_vertices);
}

namespace {
// The options add_enhance_options registered: the option table checks their values.
std::set<const CLI::Option*>& table_checked_options() {
  static std::set<const CLI::Option*> options;
  return options;
}
}  // namespace

void require_finite_numbers(CLI::App& app) {
  for (CLI::Option* option : app.get_options()) {
    if (option->get_type_name().rfind("FLOAT", 0) != 0 || table_checked_options().count(option) > 0) continue;
    const std::string name = option->get_name();
    // transform() puts the check first, so a range check never sees a NaN or infinity (nor
    // prints inf against a range in 309 digits). Thrown as std::invalid_argument (not CLI11's
    // ValidationError, which CLI11 reports itself) for main()'s one-line error.
    option->transform(CLI::Validator(
        [name](std::string& text) {
          double value = 0;
          if (CLI::detail::lexical_cast(text, value) && !std::isfinite(value))
            throw std::invalid_argument(name + ": " + text + " is not a finite number");
          return std::string();
        },
        ""));
  }
  for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) require_finite_numbers(*sub);
}

namespace {

// "[-90, 90]", "> 0" or ">= 0" for a CLI11 range check, from its description ("FLOAT in [-90 -
// 90]", "POSITIVE", "NONNEGATIVE"; CLI11 keeps no other trace of the bounds); empty for any
// other check. The bounds are printed as CLI11 printed them (at most 6 digits), in plain numbers.
std::string cli11_range_text(const std::string& description) {
  if (description == "POSITIVE") return "> 0";
  if (description == "NONNEGATIVE") return ">= 0";
  std::smatch m;
  if (!std::regex_match(description, m, std::regex(R"((?:INT|UINT|FLOAT) in \[(\S+) - (\S+)\])"))) return {};
  if (std::strtod(m[2].str().c_str(), nullptr) >= 1e308) return ">= " + m[1].str();
  return "[" + m[1].str() + ", " + m[2].str() + "]";
}

// Why `text` is not a value of an option of CLI11 type `type` (INT, UINT or FLOAT); empty if it
// is one. Integers in decimal digits: CLI11's own conversion clamps an overflow to the largest
// value silently and reads "-1" as 2^64 - 1 for an unsigned option.
std::string not_a_number(const std::string& type, const std::string& text) {
  const char* begin = text.data() + (text.rfind('+', 0) == 0 ? 1 : 0);
  const char* end = text.data() + text.size();
  if (type == "FLOAT") {
    double value = 0;
    return CLI::detail::lexical_cast(text, value) ? std::string() : "'" + text + "' is not a number";
  }
  std::from_chars_result r{};
  if (type == "UINT") {
    unsigned long long value = 0;
    r = std::from_chars(begin, end, value);
  } else {
    long long value = 0;
    r = std::from_chars(begin, end, value);
  }
  if (r.ec == std::errc::result_out_of_range && r.ptr == end) return text + " is too large";
  if (r.ec != std::errc() || r.ptr != end || begin == end)
    return "'" + text + "' is not " + (type == "UINT" ? "an integer >= 0" : "an integer");
  return {};
}

}  // namespace

void plain_option_messages(CLI::App& app) {
  for (CLI::Option* option : app.get_options()) {
    const std::string full_type = option->get_type_name();
    const std::string type = full_type.substr(0, full_type.find(':'));
    if (type != "INT" && type != "UINT" && type != "FLOAT") continue;
    for (int i = 0;; ++i) {
      CLI::Validator* check = nullptr;
      try {
        check = option->get_validator(i);  // throws past the last (CLI11 gives no count)
      } catch (const CLI::OptionNotFound&) {
        break;
      }
      const std::string range = cli11_range_text(check->get_description());
      if (range.empty()) continue;
      // The check still decides (its bounds exactly); only its words change.
      check->operation([original = *check, range](std::string& text) {
        return original(text).empty() ? std::string() : text + " is not in the allowed range (" + range + ")";
      });
    }
    // First of all checks, so that no range check reads "abc" as out of range.
    option->transform(CLI::Validator([type](std::string& text) { return not_a_number(type, text); }, ""));
  }
  for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) plain_option_messages(*sub);
}

void add_enhance_options(CLI::App* command, GivenOptions& given, std::initializer_list<std::string_view> skip) {
  static const EnhanceOptions defaults;
  for (const EnhanceOptionSpec& spec : enhance_option_specs()) {
    if (spec.flag.empty() || std::find(skip.begin(), skip.end(), spec.name) != skip.end()) continue;
    const std::string flag(spec.flag), help(spec.help);
    // Each value is range-checked as it is parsed, in the table's words (one line, exit 1).
    const auto store = [&given, &spec](OptionValue value) {
      check_option_value(spec, value, OptionNaming::Cli);
      given[std::string(spec.name)] = std::move(value);
    };
    CLI::Option* option = nullptr;
    switch (spec.kind) {
      case OptionKind::Bool: {
        const bool value = !spec.flag_negates;
        command->add_flag_callback(
            flag, [store, value] { store(value); }, help);
        continue;
      }
      case OptionKind::Int:
      case OptionKind::OptionalInt:
        option = command->add_option_function<long long>(
            flag, [store](const long long& v) { store(v); }, help);
        break;
      case OptionKind::Double:
        option = command->add_option_function<double>(
            flag, [store](const double& v) { store(v); }, help);
        break;
      case OptionKind::Choice:
        option = command->add_option_function<std::string>(
            flag, [store](const std::string& v) { store(v); }, help);
        break;
      case OptionKind::Indices:
        continue;  // no flag (--pin FILE reads them)
    }
    table_checked_options().insert(option);
    const OptionValue fallback = spec.get(defaults);
    if (!std::holds_alternative<std::monostate>(fallback)) {
      std::string text = python_literal(fallback);
      if (spec.kind == OptionKind::Choice) text = std::get<std::string>(fallback);
      option->default_str(text);
    }
  }
}

HtmlReportOptions html_report_options(const std::filesystem::path& input, const std::filesystem::path& result) {
  HtmlReportOptions options;
  options.input_label = input.filename().string();
  options.result_label = result.filename().string();
  options.title = "vertexflow: " + options.input_label + " and " + options.result_label;
  return options;
}

EnhanceOptions enhance_options_from(const GivenOptions& given) {
  EnhanceOptions options;
  for (const auto& [name, value] : given) find_enhance_option(name)->set(options, value);
  return options;
}

nlohmann::json to_json(const MeshInfo& info) {
  const auto vec = [](const Eigen::Vector3d& v) { return nlohmann::json::array({v.x(), v.y(), v.z()}); };
  return {
      {"vertices", info.num_vertices},
      {"faces", info.num_faces},
      {"edges", info.num_edges},
      {"bounding_box", {{"min", vec(info.bounding_box.min)}, {"max", vec(info.bounding_box.max)}}},
      {"diagonal", info.diagonal},
      {"edge_length", {{"mean", info.edge_length_mean}, {"min", info.edge_length_min}, {"max", info.edge_length_max}}},
      {"surface_area", info.surface_area},
      {"components", info.components},
      {"boundary_loops", info.boundary_loops},
      {"euler_characteristic", info.euler_characteristic},
      {"genus", info.genus >= 0 ? nlohmann::json(info.genus) : nlohmann::json(nullptr)},
      {"manifold", info.manifold},
      {"oriented", info.oriented},
      {"closed", info.closed},
      {"non_manifold_edges", info.non_manifold_edges},
      {"non_manifold_vertices", info.non_manifold_vertices},
      {"quality", nlohmann::json(info.quality)}};
}

nlohmann::json to_json(const ReadReport& report) {
  return {{"format", describe_format(report)},
          {"ply_extra_values_lines", report.ply_extra_values_lines},
          {"polygons_triangulated", report.polygons_triangulated},
          {"polygons_fanned", report.polygons_fanned},
          {"vertices_welded", report.vertices_welded},
          {"unreferenced_vertices_removed", report.unreferenced_vertices_removed},
          {"repeated_index_faces_removed", report.repeated_index_faces_removed},
          {"duplicate_faces_removed", report.duplicate_faces_removed},
          {"zero_area_faces_removed", report.zero_area_faces_removed}};
}

}  // namespace vertexflow::cli
