// `vertexflow batch IN OUT_DIR [...]`: `enhance` over every mesh of a directory or glob, with
// --jobs files at once, a progress bar with an ETA, resumable, and a summary table
// (command_batch_core.h).
#include "cli_common.h"
#include "command_batch_core.h"

#include <fmt/format.h>

#include <cstdio>
#include <memory>
#include <stdexcept>

#include <unistd.h>

namespace vertexflow::cli {
namespace {

struct BatchCliOptions {
  std::string input;
  std::string output_dir;
  BatchOptions batch;
  bool no_projection = false;
  bool keep_boundary_free = false;
  bool no_metrics = false;
};

std::string clock_text(double seconds) {
  const long s = static_cast<long>(seconds + 0.5);
  return s >= 3600 ? fmt::format("{}:{:02}:{:02}", s / 3600, s / 60 % 60, s % 60)
                   : fmt::format("{}:{:02}", s / 60, s % 60);
}

}  // namespace

void register_batch_command(CLI::App& app, const GlobalOptions& global) {
  auto o = std::make_shared<BatchCliOptions>();
  CLI::App* command = app.add_subcommand(
      "batch",
      "Enhance every mesh of a directory or glob into OUT_DIR: failing files are reported and skipped, existing "
      "outputs skipped unless --force, a summary table written (OUT_DIR/batch_summary.csv and .json)");
  command->add_option("IN", o->input, "Directory (every file in it) or glob pattern (quoted) of input meshes")
      ->required();
  command->add_option("OUT_DIR", o->output_dir, "Output directory (created); each output has its input's file name")
      ->required();
  command->add_option("-j,--jobs", o->batch.jobs, "Files processed at once")
      ->check(CLI::Range(1, 1024))
      ->capture_default_str();
  command
      ->add_option("--threads", o->batch.file.threads,
                   "Threads per file (0: the cores divided among the jobs); results do not depend on it")
      ->check(CLI::Range(0, 1024))
      ->capture_default_str();
  add_flow_options(command, o->batch.file.flow, o->no_projection);
  command->add_flag("--free-boundary", o->keep_boundary_free, "Let boundary vertices move (default: fixed)");
  command->add_flag("--strict", o->batch.file.flow.refuse_non_manifold,
                    "Refuse (fail) non-manifold or inconsistently oriented meshes");
  command->add_flag("--no-metrics", o->no_metrics,
                    "Leave the summary's rho, CV, flips and displacement empty (saves the measurement's time)");
  command->add_flag("--force", o->batch.file.force, "Enhance files whose output exists already (default: skip them)");
  command->callback([o, &global] {
    o->batch.inputs = {o->input};
    o->batch.output_dir = o->output_dir;
    o->batch.file.flow.project_to_input = !o->no_projection;
    o->batch.file.flow.fix_boundary = !o->keep_boundary_free;
    o->batch.file.metrics = !o->no_metrics;
    const bool tty = ::isatty(STDERR_FILENO) == 1;
    if (!global.quiet) {
      o->batch.progress = [tty](const BatchProgress& p) {
        const BatchRow& row = *p.row;
        const std::string eta = p.eta >= 0 ? clock_text(p.eta) : std::string("?");
        if (tty) fmt::print(stderr, "\r\033[K");
        if (row.status == "failed") fmt::print(stderr, "vertexflow: warning: {}\n", row.error);
        if (tty) {
          constexpr int width = 30;
          const int filled = static_cast<int>(width * p.finished / p.total);
          fmt::print(stderr, "vertexflow: [{}{}] {}/{} files, {} failed, elapsed {}, ETA {}", std::string(filled, '#'),
                     std::string(width - filled, '.'), p.finished, p.total, p.failed, clock_text(p.elapsed), eta);
          if (p.finished == p.total) fmt::print(stderr, "\n");
        } else {
          fmt::print(stderr, "vertexflow: {}/{} {} {} ({:.2f} s), ETA {}\n", p.finished, p.total, row.input, row.status,
                     row.seconds_total, eta);
        }
      };
    }
    const BatchSummary summary = run_batch(o->batch);
    if (!global.quiet)
      fmt::print(
          stderr, "vertexflow: {} done, {} skipped (output exists), {} failed in {:.2f} s; summary in {} and {}\n",
          summary.done, summary.skipped, summary.failed, summary.seconds, summary.csv.string(), summary.json.string());
    if (summary.failed > 0)
      throw std::runtime_error(fmt::format("{} of {} files failed (listed in {})", summary.failed, summary.rows.size(),
                                           summary.csv.string()));
  });
}

}  // namespace vertexflow::cli
