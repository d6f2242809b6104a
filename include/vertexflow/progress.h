// Progress of long computations, for a front end to show: the engine (enhance.h, the flow, the
// fits, the report's metrics) says which phase it enters and which part of the whole task that
// phase spans. Reporting changes no computation: the results are the same bytes with or without
// a sink.
//
// The sink is the calling thread's (ProgressScope): the engine reports from the thread that
// called it, never from its worker threads, so a sink needs no locking against the engine and
// several tasks on several threads (batch jobs) each report to their own sink or to none.
// Without a sink a report costs a thread-local read. Reports come at the engine's natural steps
// (a phase, an outer iteration, a fit round), a few dozen per run, never from inner loops.
//
// Parts nest: a front end that reads, enhances and writes gives enhance() the part [0.05, 0.9]
// of its task (ProgressPart), and the flow's phases, which enhance() places within its own
// [0, 1], land within [0.05, 0.9] of the whole.
#pragma once

#include <functional>
#include <string_view>

namespace vertexflow {

/// One report: `phase` has started, and spans [begin, end] of the whole task (fractions in
/// [0, 1], begin <= end). `begin` is the part of the task done; the phase's own progress is not
/// known between begin and end (a front end may interpolate by time). Over a task `begin` never
/// decreases when the parts are laid out in the order they run, as the engine's are.
struct Progress {
  std::string_view phase;  ///< short, lower case: "reading", "curvature", "solve", "metrics"
  double begin = 0;
  double end = 0;
};

/// Receives the reports of the calling thread. May throw: the exception propagates out of the
/// computation (a front end's way to cancel).
using ProgressSink = std::function<void(const Progress&)>;

/// Installs `sink` as the calling thread's progress sink for the scope's lifetime, the whole
/// task being [0, 1]; the previous sink (and its part) come back at the end of the scope. An
/// empty sink silences the reports within the scope.
class ProgressScope {
 public:
  explicit ProgressScope(ProgressSink sink);
  ~ProgressScope();
  ProgressScope(const ProgressScope&) = delete;
  ProgressScope& operator=(const ProgressScope&) = delete;

 private:
  ProgressSink sink_;
  const ProgressSink* previous_sink_;
  double previous_begin_, previous_end_;
};

/// Reports that `phase` starts and spans [begin, end] of the current part (fractions of it,
/// clamped to [0, 1]; end below begin is taken as begin). Nothing without a sink; an empty
/// `phase` reports nothing.
void report_progress(std::string_view phase, double begin, double end);

/// A part of the current part, [begin, end] of it, for the scope's lifetime: reports made
/// within it (report_progress, nested parts) are placed within [begin, end]. Reports `phase`
/// first, as report_progress does (an empty `phase`: a part without a report of its own).
class ProgressPart {
 public:
  ProgressPart(std::string_view phase, double begin, double end);
  ~ProgressPart();
  ProgressPart(const ProgressPart&) = delete;
  ProgressPart& operator=(const ProgressPart&) = delete;

 private:
  double previous_begin_, previous_end_;
};

}  // namespace vertexflow
