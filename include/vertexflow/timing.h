// Wall-clock timing of phases, as the reports give them (seconds, monotonic clock).
#pragma once

#include <chrono>

namespace vertexflow {

using Clock = std::chrono::steady_clock;

/// Seconds elapsed since `start` (a Clock::now() taken earlier).
inline double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

}  // namespace vertexflow
