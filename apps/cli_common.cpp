#include "cli_common.h"

#include <fmt/format.h>

#include <cstdio>
#include <map>
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

Mesh read_mesh_with_warnings(const std::filesystem::path& path, const GlobalOptions& global, ReadReport* report) {
  inputs_read().push_back(path.string());
  ReadReport local;
  ReadReport& r = report ? *report : local;
  Mesh mesh = read_mesh(path, &r);
  if (!global.quiet) {
    for (const std::string& warning : r.warnings())
      fmt::print(stderr, "vertexflow: warning: {}: {}\n", path.string(), warning);
  }
  return mesh;
}

std::string describe_format(const ReadReport& report) {
  std::string s = format_name(report.format);
  if (report.format != MeshFormat::Obj) s += report.binary ? " (binary)" : " (ASCII)";
  if (report.gzip) s += ", gzip";
  return s;
}

nlohmann::json to_json(const QualityStats& stats) {
  return {{"min", stats.min},
          {"mean", stats.mean},
          {"p5", stats.p5},
          {"fraction_below_0_3", stats.fraction_below_0_3},
          {"histogram", stats.histogram}};
}

nlohmann::json to_json(const SurfaceRepairs& repairs) {
  return {{"input_split_vertices", repairs.input_split.held_vertices},
          {"input_reoriented_faces", repairs.input_split.reversed_faces},
          {"input_cut_edges", repairs.input_split.cut_edges},
          {"removed_degenerate_faces", repairs.removed_degenerate_faces},
          {"duplicated_vertices", repairs.duplicated_vertices}};
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

void add_flow_options(CLI::App* command, FlowOptions& flow, bool& no_projection) {
  command
      ->add_option("--lambda", flow.weights.lambda,
                   "Weight of the distance to the input: smaller moves vertices further (0.2 strong .. 50 faint)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  command->add_option("--mu", flow.weights.mu, "Weight of the fairness term")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  command->add_option("--iterations", flow.iterations, "Solves, curvature recomputed in between")
      ->check(CLI::Range(1, 20))
      ->capture_default_str();
  command
      ->add_option("--min-quality", flow.min_quality,
                   "Guard: no face ends below min(this, the worst input radius ratio 2r/R around its corners); "
                   "0 repairs only flips")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  command
      ->add_option("--sliver-floor", flow.sliver_floor,
                   "Guard: a face starting below --min-quality may not fall below this fraction of its input ratio")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  command
      ->add_option("--sliver-stiffness", flow.weights.sliver,
                   "Weight of the solve's term that keeps corners of faces below --min-quality from their opposite "
                   "edges (0: the guard alone)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  command
      ->add_option("--density-passes", flow.density.passes,
                   "Density-weighted centroidal passes after the solve, which move vertices towards curvature where "
                   "the mesh's connectivity holds the flow back (vertex-clustered scans); 0: the paper's flow alone "
                   "(flow.h, DensityRelaxation)")
      ->check(CLI::Range(0, 1000))
      ->capture_default_str();
  command
      ->add_option("--density-exponent", flow.density.exponent,
                   "Density passes: sizing density (0.1 + (|k1| + |k2|) * mean edge length)^this; 0 equalises areas")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  command->add_flag("--no-projection", no_projection,
                    "Leave vertices where the solve puts them instead of moving them onto the input surface");
  command
      ->add_option("--fairness", flow.weights.fairness_target,
                   "Target of the fairness term: input-normal (default; keeps the shape) or zero (the paper's)")
      ->transform(
          CLI::CheckedTransformer(std::map<std::string, FairnessTarget>{{"input-normal", FairnessTarget::InputNormal},
                                                                        {"zero", FairnessTarget::Zero}},
                                  CLI::ignore_case));
  command
      ->add_option("--feature-angle", flow.feature_angle,
                   "Dihedral angle (degrees) above which an edge is a crease vertices slide along, not across")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  command
      ->add_option("--solver", flow.solver,
                   "Linear solver: automatic (default; flow.h says how it chooses), direct, iterative or multilevel")
      ->transform(CLI::CheckedTransformer(std::map<std::string, LinearSolver>{{"automatic", LinearSolver::Automatic},
                                                                              {"direct", LinearSolver::Direct},
                                                                              {"iterative", LinearSolver::Iterative},
                                                                              {"multilevel", LinearSolver::Multilevel}},
                                          CLI::ignore_case));
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
      {"quality", to_json(info.quality)}};
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

nlohmann::json to_json(const DistanceStats& stats, double length_scale) {
  return {{"mean", stats.mean},
          {"rms", stats.rms},
          {"max", stats.max},
          {"mean_relative", stats.mean / length_scale},
          {"rms_relative", stats.rms / length_scale},
          {"max_relative", stats.max / length_scale},
          {"points", stats.points}};
}

}  // namespace vertexflow::cli
