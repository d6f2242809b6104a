// The check before a run that would not fit (issue 29): the peak memory of `enhance` estimated
// from the mesh size, against what this process can still allocate. Refusing with one line beats
// being killed by the OOM killer halfway through a ten-minute run. One place for every front end:
// the CLI's enhance, the batch engine (batch.h: a file that would not fit is that file's error)
// and the Python module (vertexflow.enhance raises MemoryError).
#pragma once

#include "vertexflow/flow.h"
#include "vertexflow/mesh.h"

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>

namespace vertexflow {

/// What require_memory_for_enhance throws: one line naming the input, the estimate and what is
/// available. Its own type so that front ends can map it (Python: MemoryError).
class InsufficientMemoryError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The whole process's peak resident memory for `enhance` on a mesh of `vertices` (bytes): a
/// fixed part plus bytes per vertex, both from the measured peaks of docs/benchmarks.md ("Fewer
/// vectors through the solve"), rounded up, plus the reference's trees and curvature per
/// reference vertex (`reference_vertices`, 0 for none). `solver` is the flow's
/// (FlowOptions::solver): LinearSolver::Iterative never builds the multilevel hierarchy and
/// peaks lower; the other choices are estimated by the multilevel path, which Automatic takes on
/// large meshes (a forced Direct factorisation's fill is not modelled). The report's metrics
/// peak below the flow, so `with_report` does not change the estimate (require_memory_for_enhance
/// names it in its message). Never throws.
std::uint64_t estimated_enhance_peak_bytes(Index vertices, bool with_report, Index reference_vertices,
                                           LinearSolver solver = LinearSolver::Automatic);

/// What this process can still allocate (bytes), and which limit says so.
struct AvailableMemory {
  std::uint64_t bytes = 0;
  std::string limited_by;  ///< "MemAvailable", "ulimit -v" or "cgroup memory.max"
};

/// The least of the system's MemAvailable (/proc/meminfo), the headroom under the address-space
/// limit (RLIMIT_AS, `ulimit -v`, less the process's VmSize) and under the cgroup's memory.max
/// (less memory.current). nullopt when none is known (not Linux, no /proc). Never throws.
std::optional<AvailableMemory> available_memory();

/// This process's resident memory now (VmRSS), in bytes; 0 if unknown.
std::uint64_t resident_bytes();
/// This process's peak resident memory so far (getrusage ru_maxrss), in bytes; 0 if unknown.
std::uint64_t peak_resident_bytes();

/// Throws InsufficientMemoryError("PATH: enhancing N vertices[ with a report] needs about X GiB
/// at its peak (...; H GiB of it held already), but only Y GiB more is available (limited_by)")
/// when the estimate (estimated_enhance_peak_bytes), less what the process already holds
/// (resident_bytes), exceeds available_memory(). `path` names the input in the message (a file's
/// path, or a word such as "enhance" for arrays). Does nothing when nothing is known.
void require_memory_for_enhance(const std::string& path, Index vertices, bool with_report, Index reference_vertices,
                                LinearSolver solver = LinearSolver::Automatic);

}  // namespace vertexflow
