// The progress line of a command on a terminal: "vertexflow: solve  45%  ETA 1:02", one line
// rewritten in place below whatever else the command prints (docs/progress.md).
#pragma once

#include "cli_common.h"

#include "vertexflow/progress.h"

#include <initializer_list>
#include <memory>
#include <string_view>
#include <vector>

namespace vertexflow::cli {

/// Shows the progress of the command that creates it, on stderr, when stderr is a terminal and
/// the command is not --quiet; otherwise it does nothing at all (no thread, no sink, stderr and
/// stdout untouched), so redirected output stays exactly what it was.
///
/// When shown: the calling thread's progress sink (progress.h) is installed for the object's
/// lifetime, so the command's own reports (report_progress, ProgressPart) and the engine's land
/// here; the line appears only once the command has run kProgressDelay seconds
/// (VERTEXFLOW_PROGRESS_DELAY=SECONDS overrides it, for tests), is redrawn at most 10 times a
/// second by a thread of its own, and is cleared ("\r\033[K") before anything else is written to
/// stderr or to stdout on a terminal (stdio's `stderr` and `stdout` are swapped for streams that
/// do so while the object lives), and when the object is destroyed: at the command's end, and on
/// an error's way out, before main() prints the error. Within a phase whose own progress is not
/// known, the percent advances with time at the rate of the phases before it, to at most 95% of
/// the phase; the ETA is the elapsed time times (1 - done) / done.
class ProgressLine {
 public:
  explicit ProgressLine(const GlobalOptions& global);
  ~ProgressLine();
  ProgressLine(const ProgressLine&) = delete;
  ProgressLine& operator=(const ProgressLine&) = delete;

  /// Whether the line is in use (a terminal, not --quiet).
  [[nodiscard]] bool active() const { return impl_ != nullptr; }
  /// `phase` started and spans [begin, end] of the command (fractions); safe from any thread
  /// (batch reports from its workers). What the thread's sink does with the engine's reports.
  void report(std::string_view phase, double begin, double end);
  /// A phase whose share of the command is not known: the line shows it with the elapsed time
  /// instead of a percent and an ETA.
  void report_unknown(std::string_view phase);
  /// Clears the line for good (before a command prints its results).
  void finish();

  /// Seconds a command runs before its line appears.
  static constexpr double kProgressDelay = 2.0;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::unique_ptr<ProgressScope> scope_;
};

/// The bounds of consecutive parts of a command whose costs are as `weights` (any unit; zero for
/// a part that does not run): part i spans [bounds[i], bounds[i + 1]] of [0, 1].
std::vector<double> progress_bounds(std::initializer_list<double> weights);

}  // namespace vertexflow::cli
