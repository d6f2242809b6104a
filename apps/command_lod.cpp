// `vertexflow lod DENSE OUT_DIR [--levels P,... | --faces N,...] [--edge-flips] [--format EXT] [--html]
// [--force]`: levels of detail of DENSE, each QEM then reference mode against DENSE (lod.h), one
// mesh per level and a summary in JSON and Markdown (docs/lod.md).
#include "cli_common.h"
#include "progress.h"

#include "vertexflow/lod.h"
#include "vertexflow/memory.h"
#include "vertexflow/render.h"
#include "vertexflow/timing.h"

#include <fmt/format.h>

#include <fstream>
#include <limits>
#include <optional>
#include <sstream>
#include <utility>

namespace vertexflow::cli {
namespace {

struct LodCommandOptions {
  std::string input;
  std::string output_dir;
  std::vector<double> percent;
  std::vector<Index> faces;
  bool edge_flips = false;
  bool free_boundary = false;
  bool keep_worse_fit = false;
  std::string format;
  bool html = false;
  bool force = false;
  Index samples = SamplingOptions{}.samples;
  SimplifyMethod simplify_method = LodOptions{}.simplify_method;
};

// "bunny" for "dir/bunny.off" and "dir/bunny.off.gz".
std::string mesh_stem(const std::filesystem::path& path) {
  std::filesystem::path p = path.filename();
  if (is_gzip_path(p)) p = p.stem();
  return p.stem().string();
}

// ".ply" for --format ply, else the input's own extension (without ".gz").
std::string level_extension(const LodCommandOptions& o) {
  if (!o.format.empty()) return "." + o.format;
  std::filesystem::path p = std::filesystem::path(o.input).filename();
  if (is_gzip_path(p)) p = p.stem();
  return lowercase_extension(p);
}

// The fields of a summary that must match for a level on disk to be taken as finished: the same
// dense mesh (path and counts) and every option that changes a level's bytes.
bool same_run(const nlohmann::json& old_summary, const nlohmann::json& summary) {
  for (const char* key : {"dense", "dense_faces", "dense_vertices"})
    if (!old_summary.contains(key) || old_summary[key] != summary[key]) return false;
  const nlohmann::json& a = old_summary.value("options", nlohmann::json::object());
  const nlohmann::json& b = summary["options"];
  for (const char* key : {"edge_flips", "keep_boundary", "keep_better_of_two", "sampling", "simplify_method"})
    if (!a.contains(key) || a[key] != b[key]) return false;
  return true;
}

// The entry of `old_summary` for the level written to `file`, or nullptr.
const nlohmann::json* finished_level(const nlohmann::json& old_summary, const std::string& file, Index target_faces) {
  if (!old_summary.contains("levels") || !old_summary["levels"].is_array()) return nullptr;
  for (const nlohmann::json& level : old_summary["levels"])
    if (level.value("file", std::string()) == file && level.value("target_faces", Index{-1}) == target_faces)
      return &level;
  return nullptr;
}

std::string number(double x) {
  return fmt::format("{:.4g}", x);
}

std::string markdown_summary(const nlohmann::json& s) {
  std::ostringstream md;
  md << fmt::format("# Levels of detail of {}\n\n", s["dense"].get<std::string>());
  md << fmt::format(
      "{} faces, {} vertices. Each level: QEM from the level before, then reference mode's fit against the dense "
      "mesh{}. Distances are two-sided, to the dense mesh, in its units (docs/metrics.md); gain = 1 - fitted / QEM "
      "mean. Kept: the level as written (QEM alone where the fit measured worse).\n\n",
      s["dense_faces"].get<Index>(), s["dense_vertices"].get<Index>(),
      s["options"]["edge_flips"].get<bool>() ? ", then edge flips towards it with refits" : "");
  md << "| level | file | faces | vertices | mean QEM | mean fitted | gain | RMS QEM | RMS fitted | Hausdorff QEM | "
        "Hausdorff fitted | kept | min quality | flipped | seconds |\n";
  md << "|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|---:|---:|---:|\n";
  for (const nlohmann::json& l : s["levels"]) {
    md << fmt::format("| {} | {} | {} | {} | {} | {} | {:+.1f}% | {} | {} | {} | {} | {}{} | {:.3f} | {} | {:.2f} |\n",
                      l["level"].get<int>(), l["file"].get<std::string>(), l["faces"].get<Index>(),
                      l["vertices"].get<Index>(), number(l["qem"]["mean"]), number(l["fitted"]["mean"]),
                      100 * l["mean_gain"].get<double>(), number(l["qem"]["rms"]), number(l["fitted"]["rms"]),
                      number(l["qem"]["hausdorff"]), number(l["fitted"]["hausdorff"]), l["kept"].get<std::string>(),
                      l.value("fit_skipped", false) ? " (on DENSE: not fitted)"
                      : l.value("resumed", false)   ? " (earlier run)"
                                                    : "",
                      l["min_quality"].get<double>(), l["flipped_faces"].get<Index>(),
                      l["seconds"]["total"].get<double>());
  }
  md << fmt::format("\nWall time {:.2f} s; peak memory {:.0f} MiB.\n", s["seconds"].get<double>(),
                    s["peak_memory_bytes"].get<double>() / (1024.0 * 1024.0));
  return md.str();
}

// A page with the dense mesh and the levels side by side (one PNG each beside the page, the
// same camera frame: the dense mesh's box), and the summary's table.
void write_html_page(const std::filesystem::path& page, const std::string& stem, const Mesh& dense,
                     const std::vector<const Mesh*>& meshes, const nlohmann::json& s) {
  RenderOptions ro;
  ro.width = 400;
  ro.height = 400;
  ro.view = RenderView::Front;
  ro.wireframe = true;
  ro.shading = RenderShading::Flat;
  ro.frame = bounding_box(dense.V);
  std::ostringstream html;
  html << "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>Levels of detail of " << stem
       << "</title>\n<style>body{font-family:sans-serif} figure{display:inline-block;margin:4px;text-align:center} "
          "table{border-collapse:collapse} td,th{border:1px solid #ccc;padding:2px 6px;text-align:right}</style>"
          "</head><body>\n<h1>Levels of detail of "
       << s["dense"].get<std::string>() << "</h1>\n<div>\n";
  // meshes[0] is the dense mesh, meshes[i] level i.
  for (std::size_t i = 0; i < meshes.size(); ++i) {
    const std::string png = fmt::format("{}_lod{}.png", stem, i);
    write_png(page.parent_path() / png, render_mesh(*meshes[i], ro));
    html << fmt::format(
        "<figure><img src=\"{}\" width=\"{}\" height=\"{}\"><figcaption>{}: {} faces</figcaption>"
        "</figure>\n",
        png, ro.width, ro.height, i == 0 ? std::string("dense") : fmt::format("level {}", i), meshes[i]->num_faces());
  }
  html << "</div>\n<table><tr><th>level</th><th>faces</th><th>mean QEM</th><th>mean fitted</th><th>gain</th>"
          "<th>RMS QEM</th><th>RMS fitted</th><th>Hausdorff QEM</th><th>Hausdorff fitted</th><th>kept</th>"
          "<th>min quality</th><th>seconds</th></tr>\n";
  for (const nlohmann::json& l : s["levels"])
    html << fmt::format(
        "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{:+.1f}%</td><td>{}</td><td>{}</td>"
        "<td>{}</td><td>{}</td><td>{}</td><td>{:.3f}</td><td>{:.2f}</td></tr>\n",
        l["level"].get<int>(), l["faces"].get<Index>(), number(l["qem"]["mean"]), number(l["fitted"]["mean"]),
        100 * l["mean_gain"].get<double>(), number(l["qem"]["rms"]), number(l["fitted"]["rms"]),
        number(l["qem"]["hausdorff"]), number(l["fitted"]["hausdorff"]), l["kept"].get<std::string>(),
        l["min_quality"].get<double>(), l["seconds"]["total"].get<double>());
  html << "</table>\n</body></html>\n";
  write_text_file(page, html.str());
}

}  // namespace

void register_lod_command(CLI::App& app, const GlobalOptions& global) {
  auto o = std::make_shared<LodCommandOptions>();
  CLI::App* command = app.add_subcommand(
      "lod", "Levels of detail: QEM, then reference mode's fit against DENSE, level after level (docs/lod.md)");
  command->add_option("DENSE", o->input, "The dense mesh (a non-manifold one is split as simplify splits it)")
      ->required();
  command->add_option("OUT_DIR", o->output_dir, "Directory for the levels and the summaries (created if missing)")
      ->required();
  CLI::Option_group* budget = command->add_option_group("levels", "At most one of");
  budget
      ->add_option("--levels", o->percent,
                   "Percent of DENSE's faces per level, strictly decreasing, comma-separated (default 50,25,10,5,2,1)")
      ->delimiter(',')
      ->check(CLI::Range(0.0, 100.0));
  budget->add_option("--faces", o->faces, "Faces per level, strictly decreasing, comma-separated")
      ->delimiter(',')
      ->check(CLI::PositiveNumber);
  budget->require_option(0, 1);
  command->add_flag("--edge-flips", o->edge_flips, "After each fit, flip edges towards DENSE and refit");
  command->add_flag("--free-boundary", o->free_boundary, "Let boundary edges collapse and boundary vertices move");
  command
      ->add_option("--simplify-method", o->simplify_method,
                   "QEM of each level: native (default; vertexflow's own, area-weighted quadrics) or cgal (CGAL's "
                   "edge collapse)")
      ->transform(CLI::CheckedTransformer(simplify_method_names(), CLI::ignore_case))
      ->default_str("native");
  command->add_flag("--keep-worse-fit", o->keep_worse_fit,
                    "Keep the fitted level even where QEM alone measures a smaller mean distance");
  command->add_option("--format", o->format, "Format of the level meshes (default: DENSE's)")
      ->check(CLI::IsMember({"ply", "obj", "off", "stl", "gltf", "glb"}));
  command->add_option("--samples", o->samples, "Area-uniform samples per distance measurement")
      ->check(CLI::Range(Index{0}, Index{100000000}))
      ->capture_default_str();
  command->add_flag("--html", o->html, "Also write STEM_lod.html: the levels side by side (PNGs beside it)");
  command->add_flag("--force", o->force, "Recompute levels an earlier run in OUT_DIR finished");
  command->callback([o, &global] {
    const auto start = Clock::now();
    LodOptions options;
    if (!o->percent.empty()) options.percent = o->percent;
    options.faces = o->faces;
    options.edge_flips = o->edge_flips;
    options.keep_boundary = !o->free_boundary;
    options.keep_better_of_two = !o->keep_worse_fit;
    options.simplify_method = o->simplify_method;
    options.sampling.samples = o->samples;

    // The levels' order and ranges before anything is read (the counts need DENSE's faces).
    lod_face_budgets(std::numeric_limits<Index>::max() / 4, options);
    const std::filesystem::path dir(o->output_dir);
    const std::string stem = mesh_stem(o->input);
    const std::string ext = level_extension(*o);
    if (!is_mesh_path("x" + ext)) throw IoError(o->input + ": no mesh format for the levels; give --format");
    if (std::filesystem::exists(dir) && !std::filesystem::is_directory(dir))
      throw IoError(o->output_dir + ": is not a directory");
    const bool dir_existed = std::filesystem::exists(dir);
    std::filesystem::create_directories(dir);
    // A directory this run made goes again if the run fails before writing into it (a bad or
    // unreadable DENSE): nothing is left behind. One with levels in it stays, to be resumed.
    struct RemoveIfEmpty {
      std::filesystem::path dir;
      bool armed;
      ~RemoveIfEmpty() {
        std::error_code error;
        if (armed && std::filesystem::is_empty(dir, error) && !error) std::filesystem::remove(dir, error);
      }
    } const made_here{dir, !dir_existed};
    const std::filesystem::path json_path = dir / (stem + "_lod.json"), md_path = dir / (stem + "_lod.md"),
                                html_path = dir / (stem + "_lod.html");
    check_outputs({o->input}, {{json_path}, {md_path}, {o->html ? html_path : std::filesystem::path()}}, false);
    auto say = [&](const std::string& what) {
      if (!global.quiet) fmt::print(stderr, "vertexflow: {}\n", what);
    };
    EnhanceCallbacks callbacks;
    callbacks.warning = [&](const std::string& what) {
      if (!global.quiet) fmt::print(stderr, "vertexflow: warning: {}: {}\n", o->input, what);
    };

    ProgressLine progress(global);
    say("reading " + o->input);
    report_progress("reading " + o->input, 0, 0.03);
    Mesh dense_mesh = read_mesh_with_warnings(o->input, global);
    warn_attributes_dropped(o->input, dense_mesh, "lod", global);
    dense_mesh = in_morton_order(dense_mesh);  // the chain's order, as lod() runs it (lod.h)
    const Index dense_faces = dense_mesh.num_faces(), dense_vertices = dense_mesh.num_vertices();
    std::vector<Index> budgets;
    try {
      budgets = lod_face_budgets(dense_faces, options);
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error(o->input + ": " + e.what());
    }
    std::vector<std::filesystem::path> level_paths;
    for (std::size_t i = 0; i < budgets.size(); ++i) {
      level_paths.push_back(dir / fmt::format("{}_lod{}_{}{}", stem, i + 1, budgets[i], ext));
      check_outputs({o->input}, {{level_paths.back(), /*mesh=*/true}}, false);
    }

    nlohmann::json summary;
    summary["dense"] = o->input;
    summary["dense_faces"] = dense_faces;
    summary["dense_vertices"] = dense_vertices;
    summary["options"] = lod_options_json(options);
    summary["levels"] = nlohmann::json::array();
    // An earlier run's summary: its levels whose files are still there are finished, unless
    // --force or anything that changes their bytes differs.
    nlohmann::json old_summary;
    if (!o->force && std::filesystem::exists(json_path)) {
      std::ifstream in(json_path);
      old_summary = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
      if (old_summary.is_discarded() || !old_summary.is_object() || !same_run(old_summary, summary))
        old_summary = nlohmann::json();
    }
    // Levels 1 .. first_new (exclusive) were finished by an earlier run: their files are there and
    // its summary has them. Every later level is made anew, from the one before it.
    std::size_t first_new = 0;
    while (first_new < budgets.size() && std::filesystem::exists(level_paths[first_new]) &&
           finished_level(old_summary, level_paths[first_new].filename().string(), budgets[first_new]))
      ++first_new;
    std::vector<Mesh> kept_levels;  // for the page
    // The mesh the next level is simplified from: DENSE, then each level as kept.
    Mesh previous;
    for (std::size_t i = 0; i < first_new; ++i) {
      nlohmann::json entry = *finished_level(old_summary, level_paths[i].filename().string(), budgets[i]);
      entry["resumed"] = true;
      summary["levels"].push_back(std::move(entry));
      say(fmt::format("level {}: {} was finished by an earlier run, kept (--force makes it anew)", i + 1,
                      level_paths[i].string()));
      if (o->html || (i + 1 == first_new && first_new < budgets.size())) {
        previous = read_mesh_with_warnings(level_paths[i], global);
        if (o->html) kept_levels.push_back(previous);
      }
    }
    std::optional<ReferenceSurface> dense;
    std::optional<SimplifyResult> simplified;  // the next level's QEM, made alongside a measurement (lod.h)
    for (std::size_t i = first_new; i < budgets.size(); ++i) {
      const std::string file = level_paths[i].filename().string();
      const double n = static_cast<double>(budgets.size());
      const ProgressPart part(fmt::format("level {}", i + 1), 0.03 + 0.95 * static_cast<double>(i) / n,
                              0.03 + 0.95 * static_cast<double>(i + 1) / n);
      if (!dense) {  // D's tree and samples, once for every level (reference_surface.h)
        Mesh copy = dense_mesh;
        dense.emplace(std::move(copy.V), std::move(copy.F), o->input);
      }
      say(fmt::format("level {}: simplifying to {} faces and fitting to {}", i + 1, budgets[i], o->input));
      LodLevel level;
      try {
        const Index next = i + 1 < budgets.size() ? budgets[i + 1] : 0;
        level = lod_level(i == 0 ? dense_mesh : previous, *dense, budgets[i], static_cast<int>(i + 1), options,
                          callbacks, next, std::exchange(simplified, std::nullopt));
      } catch (const std::invalid_argument& e) {
        throw std::runtime_error(o->input + ": " + e.what());
      }
      const LodLevelReport& r = level.report;
      warn_about_repairs(o->input, r.simplify.repairs, global);  // as `simplify` says them
      say(
          fmt::format("level {}: {} faces, mean distance {:.4g} (QEM alone {:.4g}, {:+.1f}%), Hausdorff {:.4g} (QEM "
                      "{:.4g}), min quality {:.3f}, {:.2f} s",
                      i + 1, r.faces, r.fitted.mean, r.qem.mean, 100 * (r.fitted.mean / r.qem.mean - 1),
                      r.fitted.hausdorff, r.qem.hausdorff, r.min_quality, r.seconds));
      if (r.fit_skipped)
        say(fmt::format("level {}: QEM alone lies on {} up to rounding (RMS distance {:.3g}): not fitted", i + 1,
                        o->input, r.qem.rms));
      else if (r.kept_qem && !global.quiet)
        fmt::print(stderr,
                   "vertexflow: warning: {}: level {}: the fit measured a larger mean distance than QEM alone; the "
                   "level is QEM alone\n",
                   o->input, i + 1);
      report_progress("writing " + file, 0.97, 1);
      write_mesh_with_warnings(level_paths[i], level.mesh, global);
      nlohmann::json entry = to_json(r);
      entry["file"] = file;
      summary["levels"].push_back(std::move(entry));
      previous = std::move(level.mesh);
      simplified = std::move(level.next_simplified);
      if (o->html) kept_levels.push_back(previous);
      // The summary after every level, so that an interrupted run resumes from it.
      summary["seconds"] = seconds_since(start);
      summary["peak_memory_bytes"] = peak_resident_bytes();
      write_text_file(json_path, summary.dump(2) + "\n");
    }
    summary["seconds"] = seconds_since(start);
    summary["peak_memory_bytes"] = peak_resident_bytes();
    write_text_file(json_path, summary.dump(2) + "\n");
    write_text_file(md_path, markdown_summary(summary));
    say(fmt::format("summary written to {} and {}", json_path.string(), md_path.string()));
    if (o->html) {
      report_progress("HTML page", 0.98, 1);
      std::vector<const Mesh*> meshes{&dense_mesh};
      for (const Mesh& level : kept_levels) meshes.push_back(&level);
      write_html_page(html_path, stem, dense_mesh, meshes, summary);
      say("page written to " + html_path.string());
    }
  });
}

}  // namespace vertexflow::cli
