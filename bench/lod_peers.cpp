// Levels of detail against their peers at equal face counts (issue 30): for each dense mesh D
// and each level's budget (percent of D's faces), D simplified directly by CGAL's QEM
// (simplify.h) and by meshoptimizer's meshopt_simplify (Debian's libmeshoptimizer-dev: edge
// collapse with quadric costs, vertices kept at input positions), and the chain of `vertexflow
// lod` (lod.h) without and with edge flips; every mesh measured against D as lod.h measures
// (two-sided mean, RMS, Hausdorff, in D's units). Writes JSON and a Markdown table
// (docs/results_lod.md, which bench/make_results.py appends to docs/results.md):
//
//   build/bin/lod_peers --json build/lod_peers.json --markdown docs/results_lod.md
//       data/bunny.off data/amo.off data/armadillo-43k.obj data/horse-48k.ply data/rocker-arm.obj
//       data/camelhead.off
//
// Also measured: vertexflow's own QEM (SimplifyMethod::Native, lod's default) directly at each
// level, against CGAL's.
//
// Options: --levels 50,25,10,5,2,1 (percent); --no-flips (skip lod with flips); --samples N
// (area samples per distance, default 200000); --fit-fairness W, --fit-proximity W,
// --fit-tolerance T, --fit-rounds N, --fit-samples S (FitOptions, to explore the fit's weights);
// --simplify-method native|cgal (the chain's QEM, LodOptions::simplify_method).
#include "vertexflow/io.h"
#include "vertexflow/lod.h"
#include "vertexflow/simplify.h"
#include "vertexflow/timing.h"

#include <fmt/format.h>
#include <meshoptimizer.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

namespace {

using namespace vertexflow;

// meshopt_simplify of (V, F) to at most `target` faces, its vertices compacted; no error bound
// (target_error 1 = the whole mesh's extent), borders locked as `simplify` keeps them.
Mesh meshopt_to(const Mesh& mesh, Index target, bool lock_border) {
  std::vector<float> positions(static_cast<std::size_t>(mesh.V.rows()) * 3);
  for (Index v = 0; v < mesh.V.rows(); ++v)
    for (int k = 0; k < 3; ++k) positions[static_cast<std::size_t>(3 * v + k)] = static_cast<float>(mesh.V(v, k));
  std::vector<unsigned> indices(static_cast<std::size_t>(mesh.F.rows()) * 3);
  for (Index f = 0; f < mesh.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) indices[static_cast<std::size_t>(3 * f + k)] = static_cast<unsigned>(mesh.F(f, k));
  std::vector<unsigned> out(indices.size());
  const std::size_t count =
      meshopt_simplify(out.data(), indices.data(), indices.size(), positions.data(), positions.size() / 3,
                       3 * sizeof(float), static_cast<std::size_t>(target) * 3, 1.0f,
                       lock_border ? static_cast<unsigned>(meshopt_SimplifyLockBorder) : 0u, nullptr);
  // Keep the input's double positions of the vertices used (meshoptimizer moves none).
  std::vector<Index> remap(static_cast<std::size_t>(mesh.V.rows()), -1);
  Index used = 0;
  Mesh result;
  result.F.resize(static_cast<Index>(count / 3), 3);
  for (std::size_t i = 0; i < count; ++i) {
    Index& r = remap[out[i]];
    if (r < 0) r = used++;
    result.F(static_cast<Index>(i / 3), static_cast<Index>(i % 3)) = static_cast<int>(r);
  }
  result.V.resize(used, 3);
  for (Index v = 0; v < mesh.V.rows(); ++v)
    if (remap[static_cast<std::size_t>(v)] >= 0) result.V.row(remap[static_cast<std::size_t>(v)]) = mesh.V.row(v);
  return result;
}

nlohmann::json measured(const Mesh& m, const ReferenceSurface& dense, const SamplingOptions& sampling, double seconds) {
  const LodDistance d = lod_distance(m, dense, sampling);
  return {{"faces", m.num_faces()}, {"mean", d.mean}, {"rms", d.rms}, {"hausdorff", d.hausdorff}, {"seconds", seconds}};
}

std::vector<double> parse_list(const std::string& text) {
  std::vector<double> values;
  std::stringstream in(text);
  for (std::string item; std::getline(in, item, ',');) values.push_back(std::stod(item));
  return values;
}

std::string stem_of(const std::string& path) {
  std::string name = path.substr(path.find_last_of('/') + 1);
  return name.substr(0, name.find('.'));
}

}  // namespace

int main(int argc, char** argv) {
  LodOptions options;
  bool flips = true;
  std::string json_path, markdown_path;
  std::vector<std::string> meshes;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::cerr << "lod_peers: " << arg << " needs a value\n";
        std::exit(2);
      }
      return argv[++i];
    };
    if (arg == "--levels")
      options.percent = parse_list(next());
    else if (arg == "--no-flips")
      flips = false;
    else if (arg == "--samples")
      options.sampling.samples = std::stol(next());
    else if (arg == "--json")
      json_path = next();
    else if (arg == "--markdown")
      markdown_path = next();
    else if (arg == "--simplify-method")
      options.simplify_method = simplify_method_names().at(next());
    else if (arg == "--fit-fairness")
      options.fit.fairness = std::stod(next());
    else if (arg == "--fit-proximity")
      options.fit.proximity = std::stod(next());
    else if (arg == "--fit-tolerance")
      options.fit.tolerance = std::stod(next());
    else if (arg == "--fit-rounds")
      options.fit.max_rounds = std::stoi(next());
    else if (arg == "--fit-samples")
      options.fit.samples_per_vertex = std::stod(next());
    else if (!arg.empty() && arg[0] == '-') {
      std::cerr << "lod_peers: unknown option " << arg << "\n";
      return 2;
    } else {
      meshes.push_back(arg);
    }
  }
  if (meshes.empty()) {
    std::cerr << "usage: lod_peers [--levels P,...] [--no-flips] [--samples N] [--json OUT] [--markdown OUT] MESH...\n";
    return 2;
  }
  nlohmann::json all = nlohmann::json::array();
  try {
    for (const std::string& path : meshes) {
      // D in the order `vertexflow lod` runs its chain in (lod.h, in_morton_order), for every
      // method: each is measured against the same samples of D.
      const Mesh dense_mesh = in_morton_order(read_mesh(path));
      const ReferenceSurface dense(dense_mesh.V, dense_mesh.F, path);
      const std::vector<Index> budgets = lod_face_budgets(dense_mesh.num_faces(), options);
      nlohmann::json rows = nlohmann::json::array();
      for (std::size_t i = 0; i < budgets.size(); ++i) {
        nlohmann::json row = {{"percent", options.percent[i]}, {"target_faces", budgets[i]}};
        auto start = Clock::now();
        SimplifyOptions so;
        so.target_faces = budgets[i];
        const Mesh qem = simplify(dense_mesh.V, dense_mesh.F, so).mesh;
        row["cgal_qem"] = measured(qem, dense, options.sampling, seconds_since(start));
        start = Clock::now();
        so.method = SimplifyMethod::Native;
        const Mesh native = simplify(dense_mesh.V, dense_mesh.F, so).mesh;
        row["native_qem"] = measured(native, dense, options.sampling, seconds_since(start));
        start = Clock::now();
        const Mesh mo = meshopt_to(dense_mesh, budgets[i], true);
        row["meshoptimizer"] = measured(mo, dense, options.sampling, seconds_since(start));
        rows.push_back(std::move(row));
      }
      for (const bool with_flips : {false, true}) {
        if (with_flips && !flips) continue;
        LodOptions o = options;
        o.edge_flips = with_flips;
        const auto start = Clock::now();
        const std::vector<LodLevel> levels = lod(dense, o);
        const double seconds = seconds_since(start);
        for (std::size_t i = 0; i < levels.size(); ++i) {
          const LodLevelReport& r = levels[i].report;
          const LodDistance& d = r.kept_qem ? r.qem : r.fitted;
          rows[i][with_flips ? "lod_flips" : "lod"] = {{"faces", r.faces},
                                                       {"mean", d.mean},
                                                       {"rms", d.rms},
                                                       {"hausdorff", d.hausdorff},
                                                       {"kept", r.kept_qem ? "qem" : "fitted"},
                                                       {"chain_qem_mean", r.qem.mean},
                                                       {"min_quality", r.min_quality},
                                                       {"flipped_faces", r.flipped_faces},
                                                       {"seconds", r.seconds}};
        }
        rows[0][with_flips ? "lod_flips_chain_seconds" : "lod_chain_seconds"] = seconds;
      }
      std::cerr << fmt::format("lod_peers: {} done\n", path);
      for (const auto& row : rows) {
        std::cerr << fmt::format(
            "  {:>5g}% {:>7}: cgal {:.4g} native {:.4g} meshopt {:.4g} lod {:.4g} ({:+.1f}% vs cgal)",
            row["percent"].get<double>(), row["target_faces"].get<Index>(), row["cgal_qem"]["mean"].get<double>(),
            row["native_qem"]["mean"].get<double>(), row["meshoptimizer"]["mean"].get<double>(),
            row["lod"]["mean"].get<double>(),
            100 * (row["lod"]["mean"].get<double>() / row["cgal_qem"]["mean"].get<double>() - 1));
        if (row.contains("lod_flips"))
          std::cerr << fmt::format(
              " flips {:.4g} ({:+.1f}%)", row["lod_flips"]["mean"].get<double>(),
              100 * (row["lod_flips"]["mean"].get<double>() / row["cgal_qem"]["mean"].get<double>() - 1));
        std::cerr << "\n";
      }
      all.push_back({{"mesh", path},
                     {"name", stem_of(path)},
                     {"faces", dense_mesh.num_faces()},
                     {"vertices", dense_mesh.num_vertices()},
                     {"levels", rows}});
    }
  } catch (const std::exception& e) {
    std::cerr << "lod_peers: " << e.what() << "\n";
    return 1;
  }

  // Averages over the levels from 50% to 2% (issue 30's acceptance), per mesh and over all.
  std::ostringstream md;
  md << "## Levels of detail: `vertexflow lod` against CGAL's QEM and meshoptimizer\n\n"
     << "Generated by `build/bin/lod_peers` (bench/lod_peers.cpp; the command is in its header). Each dense mesh "
        "D is simplified to each level's face count directly by CGAL's QEM (`vertexflow simplify`) and by "
        "meshoptimizer 0.18's `meshopt_simplify` (borders locked, no error bound; it keeps input positions), and "
        "by the chain of `vertexflow lod` (QEM from the level before, then reference mode's fit against D; with "
        "and without `--edge-flips`). Distances to D are two-sided (mean of both directions' means; RMS; "
        "Hausdorff), relative to D's bounding-box diagonal, x 1e-4. Change: against CGAL's QEM at the same "
        "level.\n\n";
  md << "| mesh | level | faces | CGAL QEM mean | meshopt mean | lod mean | lod + flips mean | lod vs QEM | lod + "
        "flips "
        "vs QEM | lod vs meshopt | CGAL QEM Hausdorff | meshopt Hausdorff | lod Hausdorff | lod + flips Hausdorff "
        "|\n";
  md << "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  auto cell = [](const nlohmann::json& row, const char* method, const char* what, double scale) {
    return row.contains(method) ? fmt::format("{:.3f}", row[method][what].get<double>() / scale * 1e4)
                                : std::string("-");
  };
  auto change = [](const nlohmann::json& row, const char* method, const char* base) {
    return row.contains(method)
               ? fmt::format("{:+.1f}%",
                             100 * (row[method]["mean"].get<double>() / row[base]["mean"].get<double>() - 1))
               : std::string("-");
  };
  struct Sums {
    double lod_qem = 0, flips_qem = 0, lod_mo = 0, flips_mo = 0, native_qem = 0, worst = -1;
    int n = 0, n_flips = 0;
  };
  Sums total;
  std::vector<std::pair<std::string, Sums>> per_mesh;
  for (const auto& mesh : all) {
    const Mesh dense_mesh = read_mesh(mesh["mesh"].get<std::string>());
    const double scale = bounding_box(dense_mesh.V).diagonal();
    Sums s;
    for (const auto& row : mesh["levels"]) {
      md << fmt::format("| {} | {:g}% | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |\n",
                        mesh["name"].get<std::string>(), row["percent"].get<double>(), row["lod"]["faces"].get<Index>(),
                        cell(row, "cgal_qem", "mean", scale), cell(row, "meshoptimizer", "mean", scale),
                        cell(row, "lod", "mean", scale), cell(row, "lod_flips", "mean", scale),
                        change(row, "lod", "cgal_qem"), change(row, "lod_flips", "cgal_qem"),
                        change(row, "lod", "meshoptimizer"), cell(row, "cgal_qem", "hausdorff", scale),
                        cell(row, "meshoptimizer", "hausdorff", scale), cell(row, "lod", "hausdorff", scale),
                        cell(row, "lod_flips", "hausdorff", scale));
      const double p = row["percent"].get<double>();
      if (p > 50 || p < 2) continue;
      const double qem = row["cgal_qem"]["mean"], mo = row["meshoptimizer"]["mean"], l = row["lod"]["mean"];
      s.lod_qem += l / qem;
      s.lod_mo += l / mo;
      s.native_qem += row["native_qem"]["mean"].get<double>() / qem;
      s.worst = std::max(s.worst, l / qem - 1);
      ++s.n;
      if (row.contains("lod_flips")) {
        const double lf = row["lod_flips"]["mean"];
        s.flips_qem += lf / qem;
        s.flips_mo += lf / mo;
        ++s.n_flips;
      }
    }
    per_mesh.emplace_back(mesh["name"].get<std::string>(), s);
    total.lod_qem += s.lod_qem;
    total.lod_mo += s.lod_mo;
    total.native_qem += s.native_qem;
    total.flips_qem += s.flips_qem;
    total.flips_mo += s.flips_mo;
    total.worst = std::max(total.worst, s.worst);
    total.n += s.n;
    total.n_flips += s.n_flips;
  }
  md << "\nMean distance averaged over the levels from 50% to 2% (the mean of the per-level ratios, minus 1):\n\n"
     << "| mesh | lod vs CGAL QEM | lod + flips vs CGAL QEM | lod vs meshopt | lod + flips vs meshopt | lod's worst "
        "level vs CGAL QEM | native QEM alone vs CGAL QEM |\n|---|---:|---:|---:|---:|---:|---:|\n";
  auto pct = [](double sum, int n) { return n ? fmt::format("{:+.1f}%", 100 * (sum / n - 1)) : std::string("-"); };
  per_mesh.emplace_back("all", total);
  for (const auto& [name, s] : per_mesh)
    md << fmt::format("| {} | {} | {} | {} | {} | {:+.1f}% | {} |\n", name, pct(s.lod_qem, s.n),
                      pct(s.flips_qem, s.n_flips), pct(s.lod_mo, s.n), pct(s.flips_mo, s.n_flips), 100 * s.worst,
                      pct(s.native_qem, s.n));
  std::cout << md.str();
  if (!json_path.empty()) std::ofstream(json_path) << all.dump(1) << "\n";
  if (!markdown_path.empty()) std::ofstream(markdown_path) << md.str();
  return 0;
}
