// `vertexflow enhance IN OUT [...]`: the enhance engine (enhance.h) on files: parsing, reading,
// writing, printing, and the JSON and HTML reports of what it did.
#include "cli_common.h"
#include "progress.h"

#include "vertexflow/enhance.h"
#include "vertexflow/html_report.h"
#include "vertexflow/memory.h"
#include "vertexflow/provenance.h"
#include "vertexflow/timing.h"

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

struct EnhanceCli {
  std::string input;
  std::string output;
  std::string pin_file;
  std::string report_file;
  std::string html_file;
  std::string reference_file;
  GivenOptions given;
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

}  // namespace

void register_enhance_command(CLI::App& app, const GlobalOptions& global) {
  auto o = std::make_shared<EnhanceCli>();
  CLI::App* command = app.add_subcommand("enhance", "Enhance shape features by vertex flow (Ji et al. 2011)");
  command->add_option("IN", o->input, "Input mesh")->required();
  command->add_option("OUT", o->output, "Output mesh (same connectivity)")->required();
  add_enhance_options(command, o->given);
  command->add_option("--pin", o->pin_file, "File of vertex indices (0-based) to hold in place");
  command->add_option("--reference", o->reference_file,
                      "Dense mesh of the true surface, in the input's units and overlapping it: its bounding box "
                      "must overlap the input's over at least half its extent along each axis and its diagonal be "
                      "within 10x the input's (enhance.h), or it is refused. Fit the vertices to it (reference mode; "
                      "fit.h) instead of the paper's flow");
  command->add_option("--report", o->report_file, "Write a JSON report: options, timings per phase, metrics");
  command->add_option("--html", o->html_file,
                      "Write an HTML report: both meshes in 3D, colour maps, histograms, metrics");
  command->add_flag("--force", o->force, "Allow OUT to be the input file");
  command->callback([o, &global] {
    EnhanceOptions options = enhance_options_from(o->given);
    const bool on_reference = !o->reference_file.empty();
    // The mode's rules before anything is read, so a wrong combination fails at once.
    validate_enhance_options(options, on_reference, -1, OptionNaming::Cli);
    std::vector<std::filesystem::path> inputs{o->input};
    if (on_reference) inputs.emplace_back(o->reference_file);
    check_outputs(inputs, {{o->output, /*mesh=*/true, /*may_replace_input=*/true}, {o->report_file}, {o->html_file}},
                  o->force);
    if (!o->pin_file.empty()) check_pin_file(o->pin_file);
    auto phase = [&](const std::string& what) {
      if (!global.quiet) fmt::print(stderr, "vertexflow: {}\n", what);
    };
    EnhanceCallbacks callbacks;
    callbacks.phase = phase;
    callbacks.warning = [&](const std::string& what) {
      if (!global.quiet) fmt::print(stderr, "vertexflow: warning: {}: {}\n", o->input, what);
    };
    // The progress line on a terminal (progress.h), and the command's parts by their measured
    // costs (docs/benchmarks.md, size ladder, 1M-10M): reading 3.5% and writing 1.3% of a run
    // without --report, the report's metrics 26-36% of one with it; a reference is read before
    // the fit (6.5 s at 10M vertices) and the HTML report's share is a guess.
    ProgressLine progress(global);
    const bool measured = !o->report_file.empty() || !o->html_file.empty();
    const std::vector<double> part = progress_bounds(
        {3.5, on_reference ? 15.0 : 0.0, 100.0, 1.3, measured ? 45.0 : 0.0, o->html_file.empty() ? 0.0 : 5.0});
    auto start = Clock::now();
    phase("reading " + o->input);
    report_progress("reading " + o->input, part[0], part[1]);
    // The face list as the file has it (enhance.h holds what the methods cannot work on).
    ReadOptions keep_faces;
    keep_faces.keep_face_list = true;
    const Mesh mesh = read_mesh_with_warnings(o->input, global, nullptr, keep_faces);
    const double seconds_read = seconds_since(start);
    if (!o->pin_file.empty()) options.constraints.pinned = read_pins(o->pin_file, mesh.num_vertices());
    std::optional<ReferenceSurface> reference;
    if (on_reference) {
      phase("reading " + o->reference_file);
      report_progress("reading " + o->reference_file, part[1], part[2]);
      Mesh dense = read_mesh_with_warnings(o->reference_file, global);
      reference.emplace(std::move(dense.V), std::move(dense.F), o->reference_file);
    }
    const ReferenceSurface* reference_pointer = reference ? &*reference : nullptr;
    // One line now rather than the OOM killer later, or block-Jacobi alone where only the
    // multilevel preconditioner would not fit (vertexflow/memory.h).
    const EnhanceMemoryPlan memory_plan =
        plan_memory_for_enhance(o->input, mesh.num_vertices(), measured,
                                reference ? static_cast<Index>(reference->vertices().rows()) : 0, options.flow.solver);
    options.flow.solver = memory_plan.solver;
    if (!memory_plan.note.empty()) callbacks.warning(memory_plan.note);
    // Trees over the reference's faces that the run and its report build (reference_surface.h).
    const std::uint64_t trees_before = reference ? distance_trees_built(reference->faces().rows()) : 0;
    EnhanceResult result;
    // What the report's metrics can take from the run instead of building it again.
    EnhanceMetricsReuse reuse;
    try {
      const ProgressPart engine("", part[2], part[3]);
      result = measured ? enhance(mesh, reference_pointer, options, callbacks, reuse)
                        : enhance(mesh, reference_pointer, options, callbacks);
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error(o->input + ": " + e.what());
    }
    const Mesh& out = result.mesh;
    if (records_fit(result.provenance) && format_from_path(o->output) == MeshFormat::Stl && !global.quiet)
      fmt::print(stderr,
                 "vertexflow: warning: {}: STL keeps no comments, so the provenance line '{}' is lost: a later "
                 "--surface smooth run cannot tell that this mesh is already fitted (write PLY, OBJ or OFF to keep "
                 "it)\n",
                 o->output, result.provenance);
    start = Clock::now();
    phase("writing " + o->output);
    report_progress("writing " + o->output, part[3], part[4]);
    write_mesh_with_warnings(o->output, out, global);
    const double seconds_write = seconds_since(start);

    if (o->report_file.empty() && o->html_file.empty()) return;
    // Each mesh's curvature, computed once for the metrics and the HTML report.
    EnhanceCurvatures curvatures;
    nlohmann::json report = [&] {
      const ProgressPart metrics("metrics", part[4], part[5]);
      return enhance_metrics(mesh, out, reference_pointer, &curvatures, &reuse);
    }();
    reuse.clear();
    report.update(result.report);
    report["seconds"]["read"] = seconds_read;
    report["seconds"]["write"] = seconds_write;
    report["input"] = o->input;
    report["output"] = o->output;
    if (reference) {
      report["reference"] = o->reference_file;
      report["reference_trees_built"] = distance_trees_built(reference->faces().rows()) - trees_before;
      report["reference_memory_bytes"] = reference->memory_bytes();  // now with the metrics' samples
    }
    // The whole process's peak so far (the run, and the metrics above).
    report["peak_memory_bytes"] = peak_resident_bytes();
    if (!memory_plan.note.empty()) report["solver"]["chosen_for_memory"] = memory_plan.note;
    if (!o->report_file.empty()) {
      write_text_file(o->report_file, report.dump(2) + "\n");
      phase("report written to " + o->report_file);
    }
    if (!o->html_file.empty()) {
      report_progress("HTML report", part[5], part[6]);
      write_html_report(o->html_file, mesh, out, curvatures.input, curvatures.result, report.dump(),
                        html_report_options(o->input, o->output));
      phase("HTML report written to " + o->html_file);
    }
  });
}

}  // namespace vertexflow::cli
