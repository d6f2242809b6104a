// Memory estimate before a run (memory.h).
#include "vertexflow/memory.h"

#include <fmt/format.h>

#include <sys/resource.h>

#include <algorithm>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace vertexflow {
namespace {

// Peak RSS = fixed part + bytes per vertex, fitted to the whole-process peaks measured at 1M and
// 10M vertices and rounded up (docs/benchmarks.md, "Float storage in the solve, and the first
// coarse matrix by its upper half"). Above the fixed part: the multilevel path 609 B/vertex at
// 1,081,027 vertices (arm1m, --solver multilevel, 823,164 KB) and 622 at 9,729,227 (arm10m, the
// default, 6,088,980 KB), 635 and 627 with --report (850,848 and 6,140,620 KB); block-Jacobi
// alone (--solver iterative) 456 at 1M (661,500 KB), and with --report, whose metrics are then
// the peak, 605 at 1M (819,372 KB) and 624 at 10M (6,108,084 KB). With a report both paths peak
// alike, so the estimates are of runs with one, block-Jacobi's a little lower. The fixed part
// is as fitted before (128 MiB before the CLI's jemalloc, which holds up to about 40 MB more on
// small meshes: a 163,842-vertex sphere 224.7 -> 265.7 MB with thp:always alone). A reference
// vertex (its V and F, trees, samples and curvature) measured 181-182 B: a 100,002-vertex QEM of
// arm1m fitted to arm1m, arm10m and arm27m with --report peaked at 398.5, 1,963.4 and 5,118.9 MB,
// linear in the reference's 1.08M, 9.73M and 27.0M vertices; sphere_low fitted to Loop
// subdivisions of sphere.off (257k and 1.03M vertices) 153 B. 250 leaves a margin for fits that
// take more rounds (docs/benchmarks.md, "The reference's part of the estimate").
constexpr double kFixedBytes = 176.0 * 1024 * 1024;
constexpr double kBytesPerVertexMultilevel = 680;
constexpr double kBytesPerVertexBlockJacobi = 650;
constexpr double kReferenceBytesPerVertex = 250;

// A "Key:   N kB" line of a /proc file, in bytes.
std::optional<std::uint64_t> proc_kib(const char* file, const std::string& key) {
  std::ifstream in(file);
  std::string line;
  while (std::getline(in, line))
    if (line.compare(0, key.size(), key) == 0 && line.size() > key.size() && line[key.size()] == ':') {
      std::istringstream fields(line.substr(key.size() + 1));
      std::uint64_t kib = 0;
      if (fields >> kib) return kib * 1024;
    }
  return std::nullopt;
}

std::optional<std::uint64_t> read_number(const char* file) {
  std::ifstream in(file);
  std::string word;
  if (!(in >> word) || word == "max") return std::nullopt;
  try {
    return std::stoull(word);
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

double gib(std::uint64_t bytes) {
  return static_cast<double>(bytes) / (1024.0 * 1024.0 * 1024.0);
}

}  // namespace

std::uint64_t estimated_enhance_peak_bytes(Index vertices, bool /*with_report*/, Index reference_vertices,
                                           LinearSolver solver) {
  const double per_vertex = solver == LinearSolver::Iterative ? kBytesPerVertexBlockJacobi : kBytesPerVertexMultilevel;
  return static_cast<std::uint64_t>(kFixedBytes + per_vertex * vertices +
                                    kReferenceBytesPerVertex * reference_vertices);
}

std::optional<AvailableMemory> available_memory() {
  std::optional<AvailableMemory> least;
  auto consider = [&](std::optional<std::uint64_t> bytes, const char* what) {
    if (bytes && (!least || *bytes < least->bytes)) least = AvailableMemory{*bytes, what};
  };
  consider(proc_kib("/proc/meminfo", "MemAvailable"), "MemAvailable");
  rlimit limit{};
  if (getrlimit(RLIMIT_AS, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY) {
    const std::uint64_t used = proc_kib("/proc/self/status", "VmSize").value_or(0);
    consider(limit.rlim_cur > used ? limit.rlim_cur - used : 0, "ulimit -v");
  }
  if (const auto max = read_number("/sys/fs/cgroup/memory.max")) {
    const std::uint64_t current = read_number("/sys/fs/cgroup/memory.current").value_or(0);
    consider(*max > current ? *max - current : 0, "cgroup memory.max");
  }
  return least;
}

std::uint64_t resident_bytes() {
  return proc_kib("/proc/self/status", "VmRSS").value_or(0);
}

std::uint64_t peak_resident_bytes() {
  rusage usage{};
  if (getrusage(RUSAGE_SELF, &usage) != 0) return 0;
  return static_cast<std::uint64_t>(usage.ru_maxrss) * 1024;  // KiB on Linux
}

EnhanceMemoryPlan plan_memory_for_enhance(const std::string& path, Index vertices, bool with_report,
                                          Index reference_vertices, LinearSolver solver,
                                          const std::optional<AvailableMemory>& available, std::uint64_t held) {
  EnhanceMemoryPlan plan{solver, {}};
  if (!available) return plan;
  const auto estimate = [&](LinearSolver s) {
    return estimated_enhance_peak_bytes(vertices, with_report, reference_vertices, s);
  };
  const auto fits = [&](std::uint64_t bytes) { return (bytes > held ? bytes - held : 0) <= available->bytes; };
  const std::uint64_t wanted = estimate(solver);
  if (fits(wanted)) return plan;
  std::uint64_t least = wanted;  // the estimate the refusal names: the lightest path allowed
  if (solver == LinearSolver::Automatic) {
    const LinearSolver lighter = LinearSolver::Iterative;
    least = estimate(lighter);
    if (fits(least)) {
      plan.solver = lighter;
      plan.note = fmt::format(
          "the multilevel preconditioner would need about {:.2f} GiB at the peak ({:.2f} GiB of it held already), "
          "but only {:.2f} GiB more is available ({}), so the flow runs block-Jacobi alone (about {:.2f} GiB; slower "
          "on large flat regions)",
          gib(wanted), gib(held), gib(available->bytes), available->limited_by, gib(least));
      return plan;
    }
  }
  throw InsufficientMemoryError(
      fmt::format("{}: enhancing {} vertices{} needs about {:.2f} GiB at its peak (estimated from measured runs, "
                  "docs/benchmarks.md; {:.2f} GiB of it held already), but only {:.2f} GiB more is available ({})",
                  path, vertices, with_report ? " with a report" : "", gib(least), gib(held), gib(available->bytes),
                  available->limited_by));
}

EnhanceMemoryPlan plan_memory_for_enhance(const std::string& path, Index vertices, bool with_report,
                                          Index reference_vertices, LinearSolver solver) {
  const std::optional<AvailableMemory> available = available_memory();
  return plan_memory_for_enhance(path, vertices, with_report, reference_vertices, solver, available,
                                 available ? resident_bytes() : 0);
}

}  // namespace vertexflow
