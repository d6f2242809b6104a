// The CLI's check before a run that would not fit (issue 29): the peak memory of `enhance`
// estimated from the mesh size, against what this process can still allocate. Refusing with one
// line beats being killed by the OOM killer halfway through a ten-minute run.
#pragma once

#include "vertexflow/mesh.h"

#include <cstdint>
#include <optional>
#include <string>

namespace vertexflow::cli {

/// The whole process's peak resident memory for `enhance` on a mesh of `vertices` (bytes), from
/// the measured peaks per vertex of docs/benchmarks.md ("Memory by phase"), rounded up: the
/// flow's multilevel path (the larger), the report's metrics when `with_report`, and the
/// reference's trees and curvature per reference vertex.
std::uint64_t estimated_enhance_peak_bytes(Index vertices, bool with_report, Index reference_vertices);

/// What this process can still allocate: the least of the system's MemAvailable, the headroom
/// under the address-space limit (ulimit -v) and under the cgroup's memory.max. nullopt when
/// none is known.
struct AvailableMemory {
  std::uint64_t bytes = 0;
  std::string limited_by;  ///< "MemAvailable", "ulimit -v" or "cgroup memory.max"
};
std::optional<AvailableMemory> available_memory();

/// This process's resident memory now, and at its peak so far (bytes; 0 if unknown).
std::uint64_t resident_bytes();
std::uint64_t peak_resident_bytes();

/// Throws std::runtime_error("PATH: enhancing N vertices needs about X GiB ..., but only Y GiB
/// is available (limited_by)") when the estimate, less what the process already holds, exceeds
/// the memory available.
void require_memory_for_enhance(const std::string& path, Index vertices, bool with_report, Index reference_vertices);

}  // namespace vertexflow::cli
