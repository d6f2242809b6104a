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

/// What plan_memory_for_enhance throws: one line naming the input, the estimate and what is
/// available. Its own type so that front ends can map it (Python: MemoryError).
class InsufficientMemoryError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The whole process's peak resident memory for `enhance` on a mesh of `vertices` (bytes): a
/// fixed part plus bytes per vertex, both from the measured peaks of docs/benchmarks.md ("Float
/// storage in the solve, and the first coarse matrix by its upper half"), rounded up, plus the
/// reference's trees and curvature per reference vertex (`reference_vertices`, 0 for none).
/// `solver` is the flow's (FlowOptions::solver): LinearSolver::Iterative never builds the
/// multilevel hierarchy and peaks a little lower; the other choices are estimated by the
/// multilevel path, which Automatic takes on large meshes (a forced Direct factorisation's fill
/// is not modelled). The estimates are of runs with a report, whose metrics peak about as high as
/// the flow, so `with_report` does not change them (plan_memory_for_enhance names it in its
/// message). Never throws.
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

/// What enhance may run within the memory available (plan_memory_for_enhance).
struct EnhanceMemoryPlan {
  /// The solver to run: the one requested, or LinearSolver::Iterative in place of Automatic.
  LinearSolver solver = LinearSolver::Automatic;
  /// Empty, or one line saying why the solver was changed (for a warning and the report).
  std::string note;
};

/// The check before a run. The plan is `solver` when its estimate (estimated_enhance_peak_bytes),
/// less what the process already holds (`held`), fits in what is `available`. Where it does not:
/// - `solver` Automatic, and block-Jacobi alone fits (LinearSolver::Iterative: no coarse
///   hierarchy, about 150 bytes per vertex less; slower where large flat regions need the coarse
///   space): the plan runs that instead of refusing, and `note` says so. Automatic's output
///   bytes then depend on the memory available as well as on the mesh; both paths stop at the
///   same relative residual (FlowOptions::solver_tolerance), so the vertices differ by far less
///   than an edge length (docs/benchmarks.md, "Solver tolerance 1e-4").
/// - otherwise throws InsufficientMemoryError("PATH: enhancing N vertices[ with a report] needs
///   about X GiB at its peak (...; H GiB of it held already), but only Y GiB more is available
///   (limited_by)"), X the estimate of the lightest path allowed. An explicit solver is never
///   changed.
/// `path` names the input in the messages (a file's path, or a word such as "enhance" for
/// arrays). A nullopt `available` (nothing known) plans `solver` unchanged.
EnhanceMemoryPlan plan_memory_for_enhance(const std::string& path, Index vertices, bool with_report,
                                          Index reference_vertices, LinearSolver solver,
                                          const std::optional<AvailableMemory>& available, std::uint64_t held);
/// The same with what this process measures now: available_memory() and resident_bytes().
EnhanceMemoryPlan plan_memory_for_enhance(const std::string& path, Index vertices, bool with_report,
                                          Index reference_vertices, LinearSolver solver);

}  // namespace vertexflow
