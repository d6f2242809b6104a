// Shared helpers for the tests: paths to bundled data and scratch directories.
#pragma once

#include "vertexflow/mesh.h"

#include <tbb/global_control.h>

#include <filesystem>
#include <string>
#include <vector>

// Set in AddressSanitizer builds, whose reserved address space defeats address-space limits.
#if defined(__SANITIZE_ADDRESS__)
#define VERTEXFLOW_TEST_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define VERTEXFLOW_TEST_ASAN 1
#endif
#endif

namespace vertexflow::test {

/// compute() with TBB limited to `threads` threads: determinism tests compare 1 and 2.
template <class Compute>
auto with_threads(int threads, Compute&& compute) {
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threads));
  return compute();
}

/// A mesh bundled in data/ (VERTEXFLOW_DATA_DIR is set by tests/CMakeLists.txt).
inline std::filesystem::path data_path(const std::string& name) {
  return std::filesystem::path(VERTEXFLOW_DATA_DIR) / name;
}

/// A file under tests/data/ (VERTEXFLOW_TEST_DATA_DIR).
inline std::filesystem::path test_data_path(const std::string& name) {
  return std::filesystem::path(VERTEXFLOW_TEST_DATA_DIR) / name;
}

/// A fresh empty directory for one test, removed when the object goes out of scope.
class ScratchDir {
 public:
  explicit ScratchDir(const std::string& tag);
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
  ~ScratchDir();
  [[nodiscard]] const std::filesystem::path& path() const { return path_; }
  [[nodiscard]] std::filesystem::path file(const std::string& name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

/// A string made of letters, digits and '_' only, for parameterised test names.
std::string test_name(const std::string& s);

/// Result of running a shell command.
struct CommandResult {
  int exit_code = -1;  ///< exit status, or -1 if the process died from a signal
  std::string out;     ///< stdout
  std::string err;     ///< stderr
};

/// Runs `command` through /bin/sh, capturing stdout and stderr separately.
CommandResult run_command(const std::string& command);

/// Runs the built `vertexflow` CLI with `arguments` (already shell-quoted as needed).
CommandResult run_cli(const std::string& arguments);

/// What run_cli_watched saw of one run.
struct WatchedRun {
  int exit_code = -1;      ///< exit status, or -1 if the process died from a signal
  bool timed_out = false;  ///< killed by the watchdog
  std::string err;         ///< stderr
  long peak_rss_kb = 0;    ///< the child's peak resident set (getrusage ru_maxrss)
};

/// Runs the CLI with `arguments` (not through a shell) and `environment` entries
/// ("NAME=value") added to this process's environment. A watchdog kills it after
/// `timeout_seconds` (a hang, not a speed check: give it ample time).
WatchedRun run_cli_watched(const std::vector<std::string>& arguments, double timeout_seconds,
                           const std::vector<std::string>& environment = {});

/// Single-quotes a string for /bin/sh.
std::string shell_quote(const std::string& s);

/// A path single-quoted for /bin/sh.
inline std::string quoted(const std::filesystem::path& path) {
  return shell_quote(path.string());
}

/// data_path(name), single-quoted for /bin/sh: a bundled mesh as a CLI argument.
inline std::string quoted_data_path(const std::string& name) {
  return shell_quote(data_path(name).string());
}

/// Expects `output` to be manifold and oriented with the same genus, components and boundary
/// loops as `input` (gtest assertions).
void expect_same_topology(const Mesh& input, const Mesh& output);

/// Expects the guard's promises (flow.h, fit.h) of `moved` (new positions for input.F): finite,
/// no face flipped or degenerate, boundary vertices (when fix_boundary) and `pinned` vertices
/// bit for bit where they were, every face at or above stated_quality_floor (up to 1e-12).
void expect_guard_promises_kept(const Mesh& input, const Vertices& moved, bool fix_boundary,
                                const std::vector<Index>& pinned, double min_quality, double sliver_floor);

/// Expects what remesh.h and simplify.h promise of their output, and what the flow needs to
/// take it with FlowOptions::refuse_non_manifold: manifold, consistently oriented, no face of
/// zero area (degenerate_faces), no unreferenced vertex.
void expect_clean_surface(const Mesh& mesh);

/// The guard's quality floor of every face as FlowOptions::min_quality states it, computed
/// here from that text (not by the library's code): min(min_quality, the worst input radius
/// ratio of the faces around the face's corners), and for a face starting below min_quality at
/// most sliver_floor times its input ratio.
Eigen::VectorXd stated_quality_floor(const Mesh& input, double min_quality, double sliver_floor);

/// The whole content of a file (empty if it cannot be read).
std::string read_text(const std::filesystem::path& path);

/// bunny.off (data/) vertex-clustered with cells of `fraction` of its bounding-box diagonal
/// (shapes.h, vertex_clustered): how the Stanford low-resolution scans were made, non-manifold.
Mesh clustered_bunny(double fraction);

/// The redistribution rho (docs/metrics.md: the input's curvature) of `input` and of its
/// vertices moved to `moved`, as compare_meshes reports it (1,000 samples: only rho is used).
/// A non-manifold or misoriented input is measured on its manifold split (manifold_split.h):
/// the same surface, the one the flow ran on.
struct RhoChange {
  double before = 0, after = 0;
  [[nodiscard]] double gain() const { return after - before; }
};
RhoChange redistribution_rho_change(const Mesh& input, const Vertices& moved);

}  // namespace vertexflow::test
