// `vertexflow info FILE [--json]`: counts, size, topology and triangle quality of a mesh.
#include "cli_common.h"

#include "vertexflow/topology.h"

#include <fmt/format.h>

namespace vertexflow::cli {
namespace {

struct InfoOptions {
  std::string input;
  bool json = false;
};

void print_text(const std::string& file, const ReadReport& report, const MeshInfo& info) {
  const auto& b = info.bounding_box;
  fmt::print("file                  {} ({})\n", file, describe_format(report));
  fmt::print("vertices              {}\n", info.num_vertices);
  fmt::print("faces                 {}\n", info.num_faces);
  fmt::print("edges                 {}\n", info.num_edges);
  fmt::print("bounding box          [{:.6g}, {:.6g}, {:.6g}] .. [{:.6g}, {:.6g}, {:.6g}]\n", b.min.x(), b.min.y(),
             b.min.z(), b.max.x(), b.max.y(), b.max.z());
  fmt::print("diagonal              {:.6g}\n", info.diagonal);
  fmt::print("edge length           mean {:.6g}  min {:.6g}  max {:.6g}\n", info.edge_length_mean,
             info.edge_length_min, info.edge_length_max);
  fmt::print("surface area          {:.6g}\n", info.surface_area);
  fmt::print("components            {}\n", info.components);
  fmt::print("boundary loops        {}\n", info.boundary_loops);
  fmt::print("euler characteristic  {}\n", info.euler_characteristic);
  fmt::print("genus                 {}\n", info.genus >= 0 ? std::to_string(info.genus) : std::string("undefined"));
  if (info.manifold) {
    fmt::print("manifold              yes ({}, {})\n", info.closed ? "closed" : "with boundary",
               info.oriented ? "consistently oriented" : "NOT consistently oriented");
  } else {
    fmt::print("manifold              NO: {} non-manifold edges, {} non-manifold vertices\n", info.non_manifold_edges,
               info.non_manifold_vertices);
  }
  const QualityStats& q = info.quality;
  fmt::print("quality 2r/R          min {:.4f}  mean {:.4f}  p5 {:.4f}  below 0.3: {:.2f}%\n", q.min, q.mean, q.p5,
             100.0 * q.fraction_below_0_3);
}

}  // namespace

void register_info_command(CLI::App& app, const GlobalOptions& global) {
  auto options = std::make_shared<InfoOptions>();
  CLI::App* command = app.add_subcommand("info", "Print counts, size, topology and triangle quality of a mesh");
  command->add_option("FILE", options->input, "Mesh file (.obj .ply .off .stl, optionally .gz)")->required();
  command->add_flag("--json", options->json, "Print the same information as JSON");
  command->callback([options, &global] {
    ReadReport report;
    const Mesh mesh = read_mesh_with_warnings(options->input, global, &report);
    const Topology topology = build_topology(mesh.F, mesh.num_vertices());
    const MeshInfo info = describe_mesh(mesh, topology);
    if (options->json) {
      nlohmann::json out = to_json(info);
      out["file"] = options->input;
      out["read"] = to_json(report);
      fmt::print("{}\n", out.dump(2));
    } else {
      print_text(options->input, report, info);
    }
  });
}

}  // namespace vertexflow::cli
