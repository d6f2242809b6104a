// `vertexflow batch IN OUT_DIR [...]`: `enhance`, in any mode, over every mesh of a directory,
// glob or manifest, with --jobs files at once, a progress bar with an ETA, resumable, and a
// summary table (batch.h).
#include "cli_common.h"
#include "progress.h"

#include "vertexflow/batch.h"

#include <fmt/format.h>

#include <cstdio>
#include <memory>
#include <stdexcept>
#include <utility>

namespace vertexflow::cli {
namespace {

struct BatchCliOptions {
  std::string input;
  std::string output_dir;
  std::string manifest;
  std::string reference_dir;
  BatchOptions batch;
  GivenOptions given;
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
      "Enhance every mesh of a directory, glob or manifest into OUT_DIR, in any mode of `enhance`: failing files are "
      "reported and skipped, existing outputs skipped unless --force, a summary table written "
      "(OUT_DIR/batch_summary.csv and .json)");
  command->add_option("IN", o->input,
                      "Directory (every mesh file in it) or glob pattern (quoted) of input meshes; or, with "
                      "--manifest, leave it out");
  command->add_option("OUT_DIR", o->output_dir, "Output directory (created); each output has its input's file name");
  command->add_option("--manifest", o->manifest,
                      "CSV (header input,reference,output) or JSON (list of {input, reference, output}) of the files; "
                      "relative paths from the manifest's directory; a row with a reference runs reference mode");
  command->add_option("--reference-dir", o->reference_dir,
                      "Reference mode: each input's reference is the mesh of this directory with the input's stem");
  command->add_option("-j,--jobs", o->batch.jobs, "Files processed at once")
      ->check(CLI::Range(1, 1024))
      ->capture_default_str();
  command
      ->add_option("--threads", o->batch.file.threads,
                   "Threads per file (0: the cores divided among the jobs); results do not depend on it")
      ->check(CLI::Range(0, 1024))
      ->capture_default_str();
  add_enhance_options(command, o->given);
  command->add_flag("--no-metrics", o->no_metrics,
                    "Leave the summary's rho, CV, flips and displacement empty (saves the measurement's time)");
  command->add_flag("--force", o->batch.file.force, "Enhance files whose output exists already (default: skip them)");
  command->callback([o, &global] {
    // Positional arguments fill from the left: with --manifest and one positional, it is OUT_DIR.
    if (!o->manifest.empty() && o->output_dir.empty()) std::swap(o->input, o->output_dir);
    if (o->output_dir.empty()) throw std::runtime_error("batch: OUT_DIR is required");
    if (o->manifest.empty() == o->input.empty())
      throw std::runtime_error(o->manifest.empty() ? "batch: give IN (a directory or glob) or --manifest FILE"
                                                   : "batch: give IN or --manifest FILE, not both");
    if (!o->manifest.empty())
      o->batch.items = read_batch_manifest(o->manifest);
    else
      o->batch.inputs = {o->input};
    o->batch.reference_dir = o->reference_dir;
    o->batch.output_dir = o->output_dir;
    o->batch.file.enhance = enhance_options_from(o->given);
    // run_batch decides the mode from the files' references and checks the options, in the
    // flags' words, before any file is read.
    o->batch.naming = OptionNaming::Cli;
    o->batch.file.metrics = !o->no_metrics;
    // On a terminal the progress line (progress.h): files finished of all, the line moving at
    // the rate of the files so far; the engine's own phases are not shown (several files run at
    // once), so this thread's reports are silenced.
    ProgressLine line(global);
    const ProgressScope engine_reports_silenced{ProgressSink()};
    const bool tty = line.active();
    line.report("enhancing files", 0, 0);
    if (!global.quiet) {
      o->batch.warning = [](const std::string& warning) { fmt::print(stderr, "vertexflow: warning: {}\n", warning); };
      o->batch.progress = [tty, &line](const BatchProgress& p) {
        const BatchRow& row = *p.row;
        const std::string eta = p.eta >= 0 ? clock_text(p.eta) : std::string("?");
        if (row.status == "failed") fmt::print(stderr, "vertexflow: warning: {}\n", row.error);
        if (tty) {
          line.report(fmt::format("{}/{} files, {} failed", p.finished, p.total, p.failed),
                      static_cast<double>(p.finished) / p.total, static_cast<double>(p.finished + 1) / p.total);
        } else {
          fmt::print(stderr, "vertexflow: {}/{} {} {} ({:.2f} s), ETA {}\n", p.finished, p.total, row.input, row.status,
                     row.seconds_total, eta);
        }
      };
    }
    const BatchSummary summary = run_batch(o->batch);
    line.finish();
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
