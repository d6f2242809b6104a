// `vertexflow enhance IN OUT [...]`: vertex flow (paper sections 3-4), with a JSON report of
// what it did.
#include "cli_common.h"
#include "report_support.h"

#include "vertexflow/distance.h"
#include "vertexflow/edge_flips.h"
#include "vertexflow/fit.h"
#include "vertexflow/flow.h"
#include "vertexflow/html_report.h"
#include "vertexflow/provenance.h"
#include "vertexflow/quality.h"
#include "vertexflow/report_json.h"
#include "vertexflow/timing.h"
#include "vertexflow/topology.h"
#include "vertexflow/unsharp.h"

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <functional>
#include <optional>
#include <sstream>
#include <utility>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace vertexflow::cli {
namespace {

struct EnhanceOptions {
  std::string input;
  std::string output;
  std::string pin_file;
  std::string report_file;
  std::string html_file;
  FlowOptions flow;
  std::string reference_file;
  FitOptions fit;
  std::string surface = "input";
  SmoothFitOptions smooth;
  bool assume_on_surface = false;
  std::string reference_method = "fit";
  bool edge_flips = false;
  int flip_cycles = 2;
  std::string method = "flow";
  UnsharpOptions unsharp;
  bool keep_boundary_free = false;
  bool no_projection = false;
  bool force = false;
};

// Closes a file descriptor on every way out of a scope.
struct FdGuard {
  int fd;
  explicit FdGuard(int descriptor) : fd(descriptor) {}
  FdGuard(const FdGuard&) = delete;
  FdGuard& operator=(const FdGuard&) = delete;
  ~FdGuard() {
    if (fd >= 0) ::close(fd);
  }
};

// Opens a pin file that is a regular file, and returns its descriptor and size. Anything else
// is refused: a FIFO would block the command forever (O_NONBLOCK lets its open return, so it can
// be refused), a device such as /dev/zero never ends, and a directory would read as an empty
// list.
std::pair<int, std::uint64_t> open_pin_file(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) {
    const int error = errno;
    struct stat st {};
    if (error == ENXIO && ::stat(path.c_str(), &st) == 0 && S_ISSOCK(st.st_mode))
      throw IoError(path + ": is a socket, not a pin file");
    throw IoError(path + ": cannot open the pin file: " + std::strerror(error));
  }
  FdGuard guard{fd};
  struct stat st {};
  if (::fstat(fd, &st) != 0) throw IoError(path + ": cannot stat the pin file: " + std::strerror(errno));
  if (S_ISDIR(st.st_mode)) throw IoError(path + ": is a directory, not a pin file");
  if (S_ISFIFO(st.st_mode)) throw IoError(path + ": is a FIFO, not a pin file");
  if (S_ISCHR(st.st_mode) || S_ISBLK(st.st_mode)) throw IoError(path + ": is a device, not a pin file");
  if (!S_ISREG(st.st_mode)) throw IoError(path + ": is not a regular file, not a pin file");
  guard.fd = -1;
  return {fd, static_cast<std::uint64_t>(st.st_size)};
}

// Checks the pin file before the mesh is read, so a bad one fails at once.
void check_pin_file(const std::string& path) {
  const FdGuard guard{open_pin_file(path).first};
}

// Vertex indices (0-based), separated by white space; '#' starts a comment.
std::vector<Index> read_pins(const std::string& path, Index num_vertices) {
  // An index below 2^31 has at most 10 digits: listing every vertex once, with a separator,
  // takes at most 11 bytes per vertex. 16 per vertex and 1 MiB for comments and layout is room
  // for any sensible list, and still bounds what a wrong file (a log, a mesh) costs to read.
  const std::uint64_t limit = (std::uint64_t{1} << 20) + 16 * static_cast<std::uint64_t>(num_vertices);
  const auto [fd, size] = open_pin_file(path);
  FdGuard guard{fd};
  const auto too_large = [&] {
    return IoError(
        fmt::format("{}: is larger than a pin list for {} vertices can be ({} bytes)", path, num_vertices, limit));
  };
  if (size > limit) throw too_large();
  // Read to the end rather than trusting the size: the file may grow (one byte past the limit
  // is enough to refuse it).
  std::string text(static_cast<std::size_t>(size) + 1, '\0');
  std::size_t done = 0;
  for (;;) {
    if (done == text.size()) {
      if (done > limit) throw too_large();
      text.resize(std::min<std::uint64_t>(2 * text.size(), limit + 1));
    }
    const ssize_t n = ::read(fd, text.data() + done, text.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      throw IoError(path + ": cannot read the pin file: " + std::strerror(errno));
    }
    if (n == 0) break;
    done += static_cast<std::size_t>(n);
  }
  text.resize(done);

  std::vector<Index> pins;
  std::istringstream in(text);
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    line = line.substr(0, line.find('#'));
    std::istringstream words(line);
    std::string word;
    while (words >> word) {
      long long value = -1;
      std::size_t used = 0;
      try {
        value = std::stoll(word, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used != word.size() || value < 0 || value >= num_vertices)
        throw IoError(fmt::format("{}: line {}: '{}' is not a vertex index of the input (0..{})", path, number, word,
                                  num_vertices - 1));
      pins.push_back(static_cast<Index>(value));
    }
  }
  return pins;
}

// What a method did, for the report: the new positions and the report's sections that are the
// method's own (its options, what it reported, the seconds of its phases), each written by its
// to_json (report_json.h). The command adds the metrics, file names and read and write times,
// so neither method's report is squeezed into the other's.
struct MethodRun {
  Vertices V;
  nlohmann::json report;
};

using Progress = std::function<void(const std::string&)>;

// One warning line for a mesh that was run as its manifold split (manifold_split.h).
void warn_about_split(const ManifoldSplitCounts& split, const Progress& warn) {
  if (split.any())
    warn(
        fmt::format("the mesh is not manifold or not consistently oriented: {} vertices held (their faces form more "
                    "than one fan), {} faces reoriented, {} edges treated as boundaries; --strict refuses such meshes",
                    split.held_vertices, split.reversed_faces, split.cut_edges));
}

// The flow, with the caller's topology of mesh.F. Report: options, solver, guard, seconds.
MethodRun run_flow(const Mesh& mesh, const Topology& topology, const FlowOptions& options, const Progress& phase,
                   const Progress& warn, const Mesh* reference = nullptr) {
  FlowResult result = reference ? vertex_flow_on_reference(mesh.V, mesh.F, reference->V, reference->F, options)
                                : vertex_flow(mesh.V, mesh.F, topology, options);
  const FlowReport& r = result.report;
  phase(fmt::format(
      "curvature {:.3f} s, assembly {:.3f} s, solve {:.3f} s, projection {:.3f} s, guard {:.3f} s; {} vertices "
      "limited by the guard",
      r.seconds_curvature, r.seconds_assembly, r.seconds_solve, r.seconds_projection, r.seconds_guard,
      r.limited_vertices));
  if (options.density.passes > 0)
    phase(fmt::format("{} density passes {:.3f} s; {} vertices limited by their guard", options.density.passes,
                      r.seconds_density, r.density_limited_vertices));
  warn_about_split({r.held_non_manifold_vertices, r.reoriented_faces, r.cut_edges}, warn);
  MethodRun run;
  run.report = r;
  run.report["options"] = options;
  run.V = std::move(result.V);
  return run;
}

// Reference mode (fit.h): the vertices fitted to a dense mesh of the true surface. Report:
// options, the fit's rounds and distances, guard, seconds.
MethodRun run_reference(const Mesh& mesh, const Mesh& reference, const FitOptions& options, const Progress& phase) {
  FitResult result = fit_to_reference(mesh.V, mesh.F, reference.V, reference.F, options);
  const FitReport& r = result.report;
  phase(
      fmt::format("fitted in {} rounds{}: RMS distance {:.6g} -> {:.6g}; tree {:.3f} s, queries {:.3f} s, solve "
                  "{:.3f} s, guard {:.3f} s; {} vertices limited by the guard",
                  r.rounds, r.converged ? "" : " (max-rounds reached)", r.rms_distance.front(), r.rms_distance.back(),
                  r.seconds_tree, r.seconds_queries, r.seconds_solve, r.seconds_guard, r.limited_vertices));
  MethodRun run;
  run.report = r;
  run.report["options"] = options;
  run.V = std::move(result.V);
  return run;
}

// Smooth mode (fit.h): the vertices fitted to the PN-triangle estimate through them. Report: as
// reference mode, and the estimate's options.
// `fitted_by` is the input's comment that records an earlier fit (provenance.h), or nullptr.
MethodRun run_smooth(const Mesh& mesh, const SmoothFitOptions& options, const std::string* fitted_by,
                     const Progress& phase, const Progress& warn) {
  FitResult result = fit_to_smooth_surface(mesh.V, mesh.F, options);
  const FitReport& r = result.report;
  if (r.held_as_fitted)
    warn(
        fmt::format("its provenance comment '{}' records an earlier fit, which left the vertices off the surface "
                    "the faces inscribe: smooth mode, which assumes them on it, held every vertex (provenance.h; "
                    "--assume-on-surface fits anyway)",
                    fitted_by ? *fitted_by : std::string()));
  else if (r.held_as_decimated)
    warn(
        fmt::format("{:.1f}% of the faces are below quality 0.3, as on decimated meshes, whose vertices lie off "
                    "the surface: smooth mode, which assumes them on it, held every vertex (fit.h; "
                    "--assume-on-surface fits anyway)",
                    100 * r.poor_face_fraction));
  else
    phase(
        fmt::format("patches {:.3f} s; fitted in {} round{}: RMS distance to them {:.6g} -> {:.6g}; {} vertices "
                    "limited by the guard",
                    r.seconds_surface, r.rounds, r.rounds == 1 ? "" : "s", r.rms_distance.front(),
                    r.rms_distance.back(), r.limited_vertices));
  MethodRun run;
  run.report = r;
  run.report["fit"]["poor_face_fraction"] = r.poor_face_fraction;
  run.report["fit"]["held_as_decimated"] = r.held_as_decimated;
  run.report["fit"]["held_as_fitted"] = r.held_as_fitted;
  run.report["fit"]["fitted_by"] = r.held_as_fitted && fitted_by ? nlohmann::json(*fitted_by) : nlohmann::json();
  run.report["options"] = options.fit;
  for (const char* unused : {"samples_per_vertex", "mesh_to_reference_weight", "seed"})
    run.report["options"].erase(unused);
  run.report["options"]["surface"] = options.surface;
  run.report["options"]["max_poor_face_fraction"] = options.max_poor_face_fraction;
  run.V = std::move(result.V);
  return run;
}

// --edge-flips: flips towards the target (the reference, or the smooth estimate of the input).
// Reference mode alternates them with a refit of the vertices on the new faces, for
// --flip-cycles cycles. The other modes flip once: the paper's flow keeps the vertices on the
// input surface, and smooth mode's fit pairs each face with its own patch, which new faces do
// not have (a closest-point refit to the estimate, tried instead, lost 1 point of mean
// distance on the 6k remeshes). Returns the report's part.
nlohmann::json flip_and_refit(const Mesh& mesh, const Mesh& reference, const EnhanceOptions& o, Mesh& out,
                              const Progress& phase) {
  const bool fit = !o.reference_file.empty();
  const auto start = Clock::now();
  const Mesh target = fit ? reference : smooth_surface_estimate(mesh.V, mesh.F, o.smooth.surface);
  const DistanceQuery to_target(target.V, target.F);
  EdgeFlipOptions flips;
  flips.min_quality = o.flow.min_quality;
  // No face may end against the input face whose index it takes (faces_turned_over, the
  // report's flip count).
  Vertices slot_normals(mesh.F.rows(), 3);
  for (Index f = 0; f < mesh.F.rows(); ++f) slot_normals.row(f) = face_normal(mesh.V, mesh.F, f).transpose();
  nlohmann::json cycles = nlohmann::json::array();
  Index total = 0;
  for (int cycle = 0; cycle < o.flip_cycles; ++cycle) {
    EdgeFlipResult flipped = flip_edges_toward(out.V, out.F, to_target, flips, &slot_normals);
    const EdgeFlipReport& r = flipped.report;
    nlohmann::json entry = {
        {"flips", r.flips}, {"passes", r.passes}, {"rms_before", r.rms_before}, {"rms_after_flips", r.rms_after}};
    total += r.flips;
    if (r.flips > 0) {
      out.F = std::move(flipped.F);
      if (fit) {
        out.V = fit_to_reference(out.V, out.F, target.V, target.F, o.fit).V;
        entry["refitted"] = true;
      }
    }
    phase(fmt::format("edge flips, cycle {}: {} flips in {} passes, RMS distance to the {} {:.6g} -> {:.6g}", cycle + 1,
                      r.flips, r.passes, fit ? "reference" : "smooth estimate", r.rms_before, r.rms_after));
    cycles.push_back(std::move(entry));
    if (r.flips == 0 || !fit) break;
  }
  return {{"cycles", cycles},
          {"flips", total},
          {"target", fit ? "reference" : "smooth estimate"},
          {"seconds", seconds_since(start)}};
}

// The unsharp-mask baseline (unsharp.h). Report: options, fixed_vertices, seconds.
MethodRun run_unsharp(const Mesh& mesh, const UnsharpOptions& options, const Progress& warn) {
  const auto start = Clock::now();
  UnsharpResult result = unsharp_mask(mesh.V, mesh.F, options);
  const double seconds = seconds_since(start);
  warn_about_split(result.non_manifold, warn);
  MethodRun run;
  run.report = result;
  run.report["options"] = options;
  run.report["seconds"] = {{"unsharp", seconds}};
  run.V = std::move(result.V);
  return run;
}

}  // namespace

void register_enhance_command(CLI::App& app, const GlobalOptions& global) {
  auto o = std::make_shared<EnhanceOptions>();
  CLI::App* command = app.add_subcommand("enhance", "Enhance shape features by vertex flow (Ji et al. 2011)");
  command->add_option("IN", o->input, "Input mesh")->required();
  command->add_option("OUT", o->output, "Output mesh (same connectivity)")->required();
  add_flow_options(command, o->flow, o->no_projection);
  command->add_option("--method", o->method, "flow (Ji et al.) or unsharp (geometric unsharp mask baseline)")
      ->check(CLI::IsMember({"flow", "unsharp"}))
      ->capture_default_str();
  CLI::Option* weight =
      command->add_option("--weight", o->unsharp.weight, "Unsharp mask: weight w of the detail added back")
          ->capture_default_str();
  CLI::Option* smoothing = command
                               ->add_option("--smoothing-iterations", o->unsharp.smoothing_iterations,
                                            "Unsharp mask: rounds of uniform Laplacian smoothing")
                               ->check(CLI::Range(0, 1000))
                               ->capture_default_str();
  command->add_option("--pin", o->pin_file, "File of vertex indices (0-based) to hold in place");
  command->add_flag("--free-boundary", o->keep_boundary_free, "Let boundary vertices move (default: fixed)");
  command->add_flag("--strict", o->flow.refuse_non_manifold,
                    "Refuse a non-manifold or inconsistently oriented mesh (default: hold its non-manifold vertices "
                    "and flow the rest)");
  command->add_option("--report", o->report_file, "Write a JSON report: options, timings per phase, metrics");
  command->add_option("--reference", o->reference_file,
                      "Dense mesh of the true surface: fit the vertices to it (reference mode; fit.h) instead of "
                      "the paper's flow");
  command
      ->add_option("--reference-method", o->reference_method,
                   "With --reference: fit (the vertices fitted to it, leaving the input surface; fit.h) or flow (the "
                   "paper's flow with its foot points, frames and curvature from the reference, the vertices on it; "
                   "flow.h)")
      ->check(CLI::IsMember({"fit", "flow"}))
      ->capture_default_str();
  command
      ->add_option("--surface", o->surface,
                   "What the vertices approximate without --reference: input (the paper's flow over the input "
                   "surface) or smooth (fit to a PN-triangle estimate of the smooth surface through the vertices; "
                   "fit.h)")
      ->check(CLI::IsMember({"input", "smooth"}))
      ->capture_default_str();
  command
      ->add_option("--max-rounds", o->fit.max_rounds,
                   "Reference and smooth modes: rounds of solve and guard at most (default 10 with --reference, "
                   "1 with --surface smooth)")
      ->check(CLI::Range(1, 100));
  command->add_flag("--assume-on-surface", o->assume_on_surface,
                    "Smooth mode: fit even inputs that look decimated (over 3% of the faces below quality 0.3), "
                    "whose vertices usually lie off the surface (fit.h)");
  command->add_flag("--edge-flips", o->edge_flips,
                    "After the method, flip edges where that brings the faces closer to the reference (or, without "
                    "one, to the smooth estimate of the input), then refit; changes connectivity, keeps the vertex "
                    "count (edge_flips.h)");
  command
      ->add_option("--flip-cycles", o->flip_cycles,
                   "--edge-flips with --reference: cycles of flips and refit (other modes flip once)")
      ->check(CLI::Range(1, 20))
      ->capture_default_str();
  command->add_option("--html", o->html_file,
                      "Write an HTML report: both meshes in 3D, colour maps, histograms, metrics");
  command->add_flag("--force", o->force, "Allow OUT to be the input file");
  command->callback([o, &global, command, weight, smoothing] {
    const bool unsharp = o->method == "unsharp";
    const bool smooth = o->surface == "smooth";
    const bool on_reference = !o->reference_file.empty();
    const bool reference_flow = on_reference && o->reference_method == "flow";
    const bool fit = on_reference && !reference_flow;
    if (command->count("--reference-method") > 0 && !on_reference)
      throw std::runtime_error("--reference-method applies to --reference only");
    if (on_reference && unsharp) throw std::runtime_error("--reference and --method unsharp exclude each other");
    if (reference_flow && smooth) throw std::runtime_error("--surface smooth and --reference exclude each other");
    if (smooth && (fit || unsharp))
      throw std::runtime_error(std::string("--surface smooth and ") + (fit ? "--reference" : "--method unsharp") +
                               " exclude each other");
    if (fit) o->method = "reference";
    if (reference_flow) o->method = "reference-flow";
    if (smooth) o->method = "smooth";
    for (const char* name :
         {"--lambda", "--mu", "--iterations", "--min-quality", "--no-projection", "--fairness", "--feature-angle",
          "--solver", "--sliver-floor", "--sliver-stiffness", "--density-passes", "--density-exponent"})
      if (unsharp && command->count(name) > 0)
        throw std::runtime_error(std::string(name) + " applies to --method flow only");
    for (const char* name : {"--lambda", "--mu", "--iterations", "--no-projection", "--fairness", "--feature-angle",
                             "--solver", "--strict", "--sliver-stiffness", "--density-passes", "--density-exponent"})
      if ((fit || smooth) && command->count(name) > 0 && !(smooth && std::string(name) == "--feature-angle"))
        throw std::runtime_error(std::string(name) + " does not apply to " +
                                 (fit ? "--reference" : "--surface smooth"));
    if (unsharp && o->edge_flips) throw std::runtime_error("--edge-flips does not apply to --method unsharp");
    if (o->edge_flips && !o->html_file.empty())
      throw std::runtime_error(
          "--html shows the input and the result on the input's faces, which --edge-flips changes");
    if (!o->edge_flips && command->count("--flip-cycles") > 0)
      throw std::runtime_error("--flip-cycles applies to --edge-flips only");
    if (!smooth && o->assume_on_surface)
      throw std::runtime_error("--assume-on-surface applies to --surface smooth only");
    if (!fit && !smooth && command->count("--max-rounds") > 0)
      throw std::runtime_error("--max-rounds applies to --reference and --surface smooth only");
    if (!unsharp && (weight->count() > 0 || smoothing->count() > 0))
      throw std::runtime_error("--weight and --smoothing-iterations apply to --method unsharp only");
    if (reference_flow && (command->count("--max-rounds") > 0 || o->edge_flips))
      throw std::runtime_error(std::string(command->count("--max-rounds") > 0 ? "--max-rounds" : "--edge-flips") +
                               " does not apply to --reference-method flow");
    std::vector<std::filesystem::path> inputs{o->input};
    if (on_reference) inputs.emplace_back(o->reference_file);
    check_outputs(inputs, {{o->output, /*mesh=*/true, /*may_replace_input=*/true}, {o->report_file}, {o->html_file}},
                  o->force);
    if (!o->pin_file.empty()) check_pin_file(o->pin_file);
    auto phase = [&](const std::string& what) {
      if (!global.quiet) fmt::print(stderr, "vertexflow: {}\n", what);
    };
    auto warn = [&](const std::string& what) {
      if (!global.quiet) fmt::print(stderr, "vertexflow: warning: {}: {}\n", o->input, what);
    };
    auto start = std::chrono::steady_clock::now();
    phase("reading " + o->input);
    Mesh mesh = read_mesh_with_warnings(o->input, global);
    const double seconds_read = seconds_since(start);
    if (!o->pin_file.empty()) o->flow.pinned = read_pins(o->pin_file, mesh.num_vertices());
    o->flow.fix_boundary = !o->keep_boundary_free;
    o->flow.project_to_input = !o->no_projection;
    o->unsharp.fix_boundary = o->flow.fix_boundary;
    o->unsharp.pinned = o->flow.pinned;
    o->unsharp.refuse_non_manifold = o->flow.refuse_non_manifold;
    o->fit.fix_boundary = o->flow.fix_boundary;
    o->fit.pinned = o->flow.pinned;
    o->fit.min_quality = o->flow.min_quality;
    o->fit.sliver_floor = o->flow.sliver_floor;
    o->smooth.surface.feature_angle = o->flow.feature_angle;
    o->smooth.fit.fix_boundary = o->fit.fix_boundary;
    o->smooth.fit.pinned = o->fit.pinned;
    o->smooth.fit.min_quality = o->fit.min_quality;
    o->smooth.fit.sliver_floor = o->fit.sliver_floor;
    if (command->count("--max-rounds") > 0) o->smooth.fit.max_rounds = o->fit.max_rounds;
    if (o->assume_on_surface) o->smooth.max_poor_face_fraction = 1.0;
    // Smooth mode holds an input that an earlier fit already moved off the inscribed surface.
    // The paper's flow (--surface input) does not count: it keeps the vertices on its input's
    // surface (provenance.h).
    const std::string* fitted_by = find_fit_provenance(mesh.comments);
    o->smooth.already_fitted = fitted_by != nullptr && !o->assume_on_surface;
    Mesh reference;
    if (on_reference) {
      phase("reading " + o->reference_file);
      reference = read_mesh_with_warnings(o->reference_file, global);
    }

    if (fit)
      phase(fmt::format("fitting {} vertices to {} ({} faces)", mesh.num_vertices(), o->reference_file,
                        reference.num_faces()));
    else if (smooth)
      phase(fmt::format("fitting {} vertices to the smooth-surface estimate through them", mesh.num_vertices()));
    else if (reference_flow)
      phase(fmt::format("flowing {} vertices over {} (lambda {}, mu {})", mesh.num_vertices(), o->reference_file,
                        o->flow.weights.lambda, o->flow.weights.mu));
    else if (unsharp)
      phase(fmt::format("unsharp mask on {} vertices (weight {}, {} smoothing iterations)", mesh.num_vertices(),
                        o->unsharp.weight, o->unsharp.smoothing_iterations));
    else
      phase(fmt::format("flowing {} vertices (lambda {}, mu {})", mesh.num_vertices(), o->flow.weights.lambda,
                        o->flow.weights.mu));
    // The topology of F, built once: the flow and both reports use it. (unsharp_mask builds its
    // own, so the baseline builds it only for a report.)
    Topology topology;
    MethodRun run;
    try {
      if (fit) {
        run = run_reference(mesh, reference, o->fit, phase);
      } else if (smooth) {
        run = run_smooth(mesh, o->smooth, fitted_by, phase, warn);
      } else if (unsharp) {
        run = run_unsharp(mesh, o->unsharp, warn);
      } else {
        topology = build_topology(mesh.F, mesh.num_vertices());
        run = run_flow(mesh, topology, o->flow, phase, warn, reference_flow ? &reference : nullptr);
      }
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error(o->input + ": " + e.what());
    }

    // Same connectivity (unless --edge-flips) and colours; per-vertex properties of the input
    // (say, curvature from an earlier run) no longer describe the moved vertices and are not
    // carried over.
    Mesh out;
    out.V = std::move(run.V);
    out.F = mesh.F;
    out.colors = mesh.colors;
    if (o->edge_flips) run.report["edge_flips"] = flip_and_refit(mesh, reference, *o, out, phase);
    // The input's provenance and a line for this run, so a chain of runs stays visible and a
    // later smooth-mode run can tell a fitted input (provenance.h).
    ProvenanceRun provenance;
    provenance.mode = fit              ? EnhanceMode::ReferenceFit
                      : reference_flow ? EnhanceMode::ReferenceFlow
                      : smooth         ? EnhanceMode::Smooth
                      : unsharp        ? EnhanceMode::Unsharp
                                       : EnhanceMode::Flow;
    provenance.reference = o->reference_file;
    provenance.edge_flips = o->edge_flips;
    provenance.assume_on_surface = o->assume_on_surface;
    if (smooth && run.report["fit"]["held_as_fitted"].get<bool>()) provenance.held = "already fitted";
    if (smooth && run.report["fit"]["held_as_decimated"].get<bool>()) provenance.held = "decimated";
    const std::string provenance_text = provenance_line(provenance);
    out.comments = mesh.comments;
    append_provenance(out.comments, provenance_text);
    run.report["provenance"] = provenance_text;
    if (records_fit(provenance_text) && format_from_path(o->output) == MeshFormat::Stl && !global.quiet)
      fmt::print(stderr,
                 "vertexflow: warning: {}: STL keeps no comments, so the provenance line '{}' is lost: a later "
                 "--surface smooth run cannot tell that this mesh is already fitted (write PLY, OBJ or OFF to keep "
                 "it)\n",
                 o->output, provenance_text);
    start = std::chrono::steady_clock::now();
    phase("writing " + o->output);
    write_mesh(o->output, out);
    const double seconds_write = seconds_since(start);

    if (!o->report_file.empty() || !o->html_file.empty()) {
      if (unsharp || fit || smooth) topology = build_topology(mesh.F, mesh.num_vertices());
      std::optional<Topology> flipped_topology;
      if (o->edge_flips) flipped_topology = build_topology(out.F, out.num_vertices());
      const Topology* result_topology = flipped_topology ? &*flipped_topology : nullptr;
      // Each mesh's curvature, computed once for the metrics and the HTML report.
      const ReportCurvatures curvatures = report_curvatures(mesh, out, topology, result_topology);
      nlohmann::json report = flow_metrics(mesh, out, topology, curvatures, result_topology);
      if (o->edge_flips) {
        // The faces differ; flips keep each face's index (edge_flips.h).
        report["flipped_faces"] = faces_turned_over(mesh.V, mesh.F, out.V, out.F);
      }
      report.update(run.report);
      report["seconds"]["read"] = seconds_read;
      report["seconds"]["write"] = seconds_write;
      report["method"] = o->method;
      report["input"] = o->input;
      report["output"] = o->output;
      if (on_reference) {
        report["reference"] = o->reference_file;
        // Two-sided, as issue 16 measures: the mean of both one-sided means, the RMS over both
        // directions, and the Hausdorff distance, in the meshes' units. The reference's tree and
        // samples (the large side) are built once for both meshes.
        const DistanceQuery to_reference(reference.V, reference.F);
        const SurfaceSamples reference_samples = sample_surface(reference.V, reference.F);
        auto two_sided = [&](const Mesh& m) {
          const SymmetricDistance d =
              symmetric_distance(one_sided_distance(sample_surface(m.V, m.F), to_reference),
                                 one_sided_distance(reference_samples, DistanceQuery(m.V, m.F)));
          return nlohmann::json{{"mean", d.mean()},
                                {"rms", d.rms()},
                                {"hausdorff", d.hausdorff},
                                {"to_reference", to_json(d.a_to_b, 1.0)},
                                {"from_reference", to_json(d.b_to_a, 1.0)}};
        };
        report["distance_to_reference"] = {{"input", two_sided(mesh)}, {"result", two_sided(out)}};
      }
      if (!o->report_file.empty()) {
        write_text_file(o->report_file, report.dump(2) + "\n");
        phase("report written to " + o->report_file);
      }
      if (!o->html_file.empty()) {
        write_html_report(o->html_file, mesh, out, curvatures.input, curvatures.result, report.dump(),
                          html_report_options(o->input, o->output));
        phase("HTML report written to " + o->html_file);
      }
    }
  });
}

}  // namespace vertexflow::cli
