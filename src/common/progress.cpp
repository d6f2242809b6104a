#include "vertexflow/progress.h"

#include <algorithm>
#include <utility>

namespace vertexflow {
namespace {

// The calling thread's sink and the current part, as fractions of the whole task.
struct ProgressState {
  const ProgressSink* sink = nullptr;
  double begin = 0, end = 1;
};

thread_local ProgressState state;

double clamp01(double x) {
  return std::clamp(x, 0.0, 1.0);
}  // NaN stays NaN: std::clamp compares

// [begin, end] of the current part as fractions of the whole task.
std::pair<double, double> place(double begin, double end) {
  const double b = clamp01(begin == begin ? begin : 0);
  const double e = std::max(b, clamp01(end == end ? end : b));
  const double width = state.end - state.begin;
  return {state.begin + width * b, state.begin + width * e};
}

}  // namespace

ProgressScope::ProgressScope(ProgressSink sink)
    : sink_(std::move(sink)), previous_sink_(state.sink), previous_begin_(state.begin), previous_end_(state.end) {
  state.sink = sink_ ? &sink_ : nullptr;
  state.begin = 0;
  state.end = 1;
}

ProgressScope::~ProgressScope() {
  state.sink = previous_sink_;
  state.begin = previous_begin_;
  state.end = previous_end_;
}

void report_progress(std::string_view phase, double begin, double end) {
  if (!state.sink || phase.empty()) return;
  const auto [b, e] = place(begin, end);
  (*state.sink)(Progress{phase, b, e});
}

ProgressPart::ProgressPart(std::string_view phase, double begin, double end)
    : previous_begin_(state.begin), previous_end_(state.end) {
  if (!state.sink) return;
  report_progress(phase, begin, end);  // may throw: the part is entered only after it
  const auto [b, e] = place(begin, end);
  state.begin = b;
  state.end = e;
}

ProgressPart::~ProgressPart() {
  state.begin = previous_begin_;
  state.end = previous_end_;
}

}  // namespace vertexflow
