// The CLI under an address-space limit (`ulimit -v`): every run ends, with exit 0 or with exit 1
// and one error line. Issue 12: OpenBLAS's pthread build started its threads as it was loaded,
// and under the limit they retried their buffers forever (the process never exited) or raised
// SIGINT (exit 130); CHOLMOD's out-of-memory was reported as "not positive definite".
#include "shapes.h"
#include "test_support.h"

#include "vertexflow/io.h"
#include "vertexflow/memory.h"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <iostream>
#include <string>
#include <utility>

namespace vertexflow {
namespace {

TEST(CliMemoryLimit, EveryRunEndsWithSuccessOrOneErrorLine) {
#ifdef VERTEXFLOW_TEST_ASAN
  GTEST_SKIP() << "AddressSanitizer reserves terabytes of address space";
#else
  const test::ScratchDir scratch("memory-limit");
  const std::string out = test::shell_quote(scratch.file("out.ply").string());
  int succeeded = 0, refused = 0;
  // From below what the dynamic loader needs for our libraries (about 250 MB of mappings here)
  // to well above what the run needs; the direct solver runs on sphere_low (589 vertices).
  for (int limit_mb = 150; limit_mb <= 600; limit_mb += 25) {
    SCOPED_TRACE("ulimit -v " + std::to_string(limit_mb) + " MB");
    const std::string limit = "ulimit -v " + std::to_string(limit_mb * 1024) + " && timeout 60 ";
    // A limit under which the process cannot even start is left out: the loader then fails
    // (exit 127), or, a few MB above, the libraries' static initialisers do, before main, when
    // jemalloc cannot map its first chunk (an abort or a crash inside jemalloc, apps/allocator.cpp).
    // `--version` runs nothing else, so it tells those limits apart.
    if (test::run_command(limit + test::shell_quote(VERTEXFLOW_CLI) + " --version").exit_code != 0) continue;
    // `timeout` is the watchdog: a hang shows as exit 124, not as a stuck test.
    const auto r = test::run_command(limit + test::shell_quote(VERTEXFLOW_CLI) + " enhance " +
                                     test::quoted_data_path("sphere_low.off") + " " + out + " --force");
    ASSERT_TRUE(r.exit_code == 0 || r.exit_code == 1) << "exit " << r.exit_code << ": " << r.err;
    if (r.exit_code == 0) {
      ++succeeded;
      continue;
    }
    ++refused;
    // One error line, the last, and it says what happened (no "not positive definite" for a
    // failed allocation, no library's own prints).
    const auto error_line = r.err.find("vertexflow: error: ");
    ASSERT_NE(error_line, std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("vertexflow: error: ", error_line + 1), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find('\n', error_line), r.err.size() - 1) << r.err;
    EXPECT_EQ(r.err.find("CHOLMOD"), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("OpenBLAS"), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("positive definite"), std::string::npos) << r.err;
  }
  // Both outcomes occur over this range, or the test proves nothing (measured in 50 MB steps:
  // 200 MB fails in the loader, 250 MB cannot start a thread, 300 MB and above succeed; the
  // 25 MB steps keep a refusal in range on a machine whose libraries map more or less. With
  // jemalloc, 2026-11-28: up to 245 MB the loader fails, 250-255 MB the static initialisers,
  // 260-275 MB are refused with one line, 300 MB and above succeed).
  EXPECT_GT(succeeded, 0);
  EXPECT_GT(refused, 0);
#endif
}

// A 655,362-vertex sphere in a scratch directory, and `vertexflow enhance` on it under an
// address-space limit (`ulimit -v`).
struct SphereUnderLimit {
  test::ScratchDir scratch;
  Mesh mesh = test::icosphere(1.0, 8);
  std::string path = scratch.file("sphere655k.ply").string(), out = scratch.file("out.ply").string();

  explicit SphereUnderLimit(const std::string& tag) : scratch(tag) { write_mesh(path, mesh); }
  [[nodiscard]] test::CommandResult enhance(std::uint64_t limit_bytes, const std::string& arguments = "") const {
    return test::run_command("ulimit -v " + std::to_string(limit_bytes / 1024) + " && " +
                             test::shell_quote(VERTEXFLOW_CLI) + " enhance " + test::shell_quote(path) + " " +
                             test::shell_quote(out) + arguments);
  }
};

// Before a run that would not fit, the CLI estimates its peak from the mesh size and stops with
// one line naming the file, the estimate and what is available (issue 29), instead of failing
// an allocation halfway or being killed. 655,362 vertices need about 0.59 GiB by the estimate
// (docs/benchmarks.md); under a 700 MB address-space limit the process has less than that left
// once the mesh is read, while the same limit runs bunny_uniform (8.9k vertices).
TEST(CliMemoryLimit, ARunThatWouldNotFitIsRefusedBeforeItStartsWithOneLine) {
#ifdef VERTEXFLOW_TEST_ASAN
  GTEST_SKIP() << "AddressSanitizer reserves terabytes of address space";
#else
  const SphereUnderLimit sphere("memory-estimate");
  const std::string& out = sphere.out;
  const std::string limit = "ulimit -v " + std::to_string(700 * 1024) + " && ";
  const auto refused = sphere.enhance(700ull << 20);
  EXPECT_EQ(refused.exit_code, 1) << refused.err;
  const std::string start = "vertexflow: error: " + sphere.path + ": enhancing 655362 vertices needs about ";
  const auto line = refused.err.find(start);
  ASSERT_NE(line, std::string::npos) << refused.err;
  EXPECT_EQ(refused.err.find('\n', line), refused.err.size() - 1) << refused.err;  // the last line, one line
  EXPECT_NE(refused.err.find("GiB more is available", line), std::string::npos) << refused.err;
  EXPECT_FALSE(std::filesystem::exists(out));
  const auto small =
      test::run_command(limit + test::shell_quote(VERTEXFLOW_CLI) + " enhance " +
                        test::quoted_data_path("bunny_uniform.off") + " " + test::shell_quote(out) + " --quiet");
  EXPECT_EQ(small.exit_code, 0) << small.err;
#endif
}

// Where only the multilevel preconditioner would not fit, `enhance` runs block-Jacobi alone, says
// so in one warning line and in the report, and writes its output. The limit is set between the
// two paths' estimates from what a refused run says about this process: a limit that refuses
// first (700 MB, as above), whose message gives what was available and held at the check.
TEST(CliMemoryLimit, WhereOnlyTheMultilevelPathWouldNotFitBlockJacobiRunsAndSaysSo) {
#ifdef VERTEXFLOW_TEST_ASAN
  GTEST_SKIP() << "AddressSanitizer reserves terabytes of address space";
#else
  const SphereUnderLimit sphere("memory-plan");
  const Mesh& mesh = sphere.mesh;
  const std::string report = sphere.scratch.file("r.json").string();
  const std::uint64_t first_limit = 700ull << 20;
  const auto refused = sphere.enhance(first_limit);
  ASSERT_EQ(refused.exit_code, 1) << refused.err;
  auto gib_before = [&](const std::string& words) {
    const auto end = refused.err.find(words);
    EXPECT_NE(end, std::string::npos) << refused.err;
    const auto begin = refused.err.rfind(' ', end - 1) + 1;
    return std::stod(refused.err.substr(begin, end - begin)) * (1ull << 30);
  };
  const double available = gib_before(" GiB more is available"), held = gib_before(" GiB of it held already");
  const double multilevel = static_cast<double>(estimated_enhance_peak_bytes(mesh.num_vertices(), true, 0));
  const double block_jacobi =
      static_cast<double>(estimated_enhance_peak_bytes(mesh.num_vertices(), true, 0, LinearSolver::Iterative));
  const double own = static_cast<double>(first_limit) - available;  // the address space at the check
  const auto limit = static_cast<std::uint64_t>(own + (multilevel + block_jacobi) / 2 - held);
  const auto r = sphere.enhance(limit, " --report " + test::shell_quote(report));
  ASSERT_EQ(r.exit_code, 0) << "ulimit -v " << limit / 1024 << ": " << r.err;
  const std::string start = "vertexflow: warning: " + sphere.path + ": the multilevel preconditioner would need about ";
  const auto line = r.err.find(start);
  ASSERT_NE(line, std::string::npos) << r.err;
  EXPECT_NE(r.err.find("so the flow runs block-Jacobi alone", line), std::string::npos) << r.err;
  const nlohmann::json j = nlohmann::json::parse(test::read_text(report));
  EXPECT_EQ(j["options"]["solver"], "conjugate gradients");  // LinearSolver::Iterative by the plan
  EXPECT_EQ(j["solver"]["method"], "conjugate gradients");   // no multilevel
  EXPECT_NE(j["solver"]["chosen_for_memory"].get<std::string>().find("block-Jacobi alone"), std::string::npos);
  EXPECT_TRUE(std::filesystem::exists(sphere.out));
#endif
}

// The estimate is an upper bound of the whole process's peak, and not a loose one, on each
// solver path it distinguishes: a 163,842-vertex sphere with a report measured 254.1 MB
// (block-Jacobi) and 277.4 MB (multilevel) against estimates of 291.0 and 296.0 MB (1.15x and
// 1.07x).
TEST(CliMemoryLimit, TheEstimateBoundsTheMeasuredPeakOnEachSolverPath) {
#ifdef VERTEXFLOW_TEST_ASAN
  GTEST_SKIP() << "the estimate is of the release CLI's peaks; AddressSanitizer's shadow memory and allocator are not";
#endif
  const test::ScratchDir scratch("estimate-bound");
  const std::string sphere = scratch.file("sphere.ply").string();
  const Mesh mesh = test::icosphere(1.0, 7);
  write_mesh(sphere, mesh);
  for (const auto& [name, solver] :
       {std::pair{"iterative", LinearSolver::Iterative}, std::pair{"multilevel", LinearSolver::Multilevel}}) {
    SCOPED_TRACE(name);
    const std::string report = scratch.file(std::string(name) + ".json").string();
    const auto r = test::run_cli("--quiet enhance " + test::shell_quote(sphere) + " " +
                                 test::shell_quote(scratch.file("out.ply").string()) + " --solver " + name +
                                 " --report " + test::shell_quote(report));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto peak = nlohmann::json::parse(test::read_text(report))["peak_memory_bytes"].get<double>();
    const auto estimate = static_cast<double>(estimated_enhance_peak_bytes(mesh.num_vertices(), true, 0, solver));
    std::cout << "[measured] " << name << ": peak " << peak / 1e6 << " MB, estimate " << estimate / 1e6 << " MB\n";
    EXPECT_LE(peak, estimate);
    EXPECT_LE(estimate, 1.5 * peak);
  }
  EXPECT_LT(estimated_enhance_peak_bytes(1000000, false, 0, LinearSolver::Iterative),
            estimated_enhance_peak_bytes(1000000, false, 0, LinearSolver::Automatic));
}

// The reference's part of the estimate bounds what a reference costs, and not loosely: a
// 642-vertex sphere fitted to a 655,362-vertex one measured 230.1-239.6 MB against an estimate
// of 348.8 MB (1.46-1.52x); without the reference's term (184.9 MB) or with its old 900 B per
// vertex (774.7 MB, 3.2x) the bounds fail.
TEST(CliMemoryLimit, TheEstimateBoundsTheMeasuredPeakInReferenceMode) {
#ifdef VERTEXFLOW_TEST_ASAN
  GTEST_SKIP() << "the estimate is of the release CLI's peaks; AddressSanitizer's shadow memory and allocator are not";
#endif
  const test::ScratchDir scratch("estimate-reference");
  const std::string coarse = scratch.file("coarse.ply").string(), dense = scratch.file("dense.ply").string();
  const Mesh input = test::icosphere(1.0, 3), reference = test::icosphere(1.0, 8);
  write_mesh(coarse, input);
  write_mesh(dense, reference);
  const std::string report = scratch.file("r.json").string();
  const auto r = test::run_cli("--quiet enhance " + test::shell_quote(coarse) + " " +
                               test::shell_quote(scratch.file("out.ply").string()) + " --reference " +
                               test::shell_quote(dense) + " --report " + test::shell_quote(report));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto peak = nlohmann::json::parse(test::read_text(report))["peak_memory_bytes"].get<double>();
  const auto estimate =
      static_cast<double>(estimated_enhance_peak_bytes(input.num_vertices(), true, reference.num_vertices()));
  std::cout << "[measured] reference mode: peak " << peak / 1e6 << " MB, estimate " << estimate / 1e6 << " MB\n";
  EXPECT_LE(peak, estimate);
  EXPECT_LE(estimate, 2 * peak);
}

// The plan before a run (memory.h) at 10M vertices, against what is available: Automatic keeps
// its path when the multilevel estimate fits, runs block-Jacobi alone (and says so) when only that
// fits, and refuses with the lighter path's estimate when neither does; an explicit solver is
// never changed, and nothing known means no check.
TEST(CliMemoryLimit, ThePlanRunsBlockJacobiAloneWhereOnlyTheMultilevelPathWouldNotFit) {
  const Index n = 10000000;
  const std::uint64_t multilevel = estimated_enhance_peak_bytes(n, false, 0, LinearSolver::Automatic);
  const std::uint64_t block_jacobi = estimated_enhance_peak_bytes(n, false, 0, LinearSolver::Iterative);
  ASSERT_LT(block_jacobi, multilevel);
  const std::uint64_t held = 500u << 20;  // the mesh, read already
  auto plan = [&](LinearSolver solver, std::uint64_t available) {
    return plan_memory_for_enhance("scan.ply", n, false, 0, solver, AvailableMemory{available, "ulimit -v"}, held);
  };
  const EnhanceMemoryPlan roomy = plan(LinearSolver::Automatic, multilevel - held);
  EXPECT_EQ(roomy.solver, LinearSolver::Automatic);
  EXPECT_TRUE(roomy.note.empty()) << roomy.note;

  const std::uint64_t between = (multilevel + block_jacobi) / 2 - held;
  const EnhanceMemoryPlan tight = plan(LinearSolver::Automatic, between);
  EXPECT_EQ(tight.solver, LinearSolver::Iterative);
  EXPECT_NE(tight.note.find("block-Jacobi alone"), std::string::npos) << tight.note;
  EXPECT_NE(tight.note.find("(ulimit -v)"), std::string::npos) << tight.note;
  EXPECT_EQ(tight.note.find('\n'), std::string::npos) << tight.note;
  EXPECT_EQ(plan(LinearSolver::Iterative, between).solver, LinearSolver::Iterative);
  try {
    plan(LinearSolver::Multilevel, between);
    ADD_FAILURE() << "an explicit multilevel run that would not fit was not refused";
  } catch (const InsufficientMemoryError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("scan.ply: enhancing 10000000 vertices needs about ", 0), 0u) << e.what();
  }
  try {
    plan(LinearSolver::Automatic, block_jacobi - held - 1);
    ADD_FAILURE() << "a run that fits on no path was not refused";
  } catch (const InsufficientMemoryError& e) {
    // The lighter path's estimate, the one that came closest.
    const std::string expected = fmt::format("needs about {:.2f} GiB", static_cast<double>(block_jacobi) / (1 << 30));
    EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
  }
  const EnhanceMemoryPlan unknown =
      plan_memory_for_enhance("scan.ply", n, false, 0, LinearSolver::Multilevel, std::nullopt, held);
  EXPECT_EQ(unknown.solver, LinearSolver::Multilevel);
}

// The report records the process's peak memory: bunny_uniform's whole run measured 83 MB.
TEST(CliMemoryLimit, TheReportRecordsThePeakMemory) {
  const test::ScratchDir scratch("peak-memory");
  const std::string out = test::shell_quote(scratch.file("out.ply").string());
  const std::string report = scratch.file("r.json").string();
  const auto r = test::run_cli("--quiet enhance " + test::quoted_data_path("bunny_uniform.off") + " " + out +
                               " --report " + test::shell_quote(report));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto peak = nlohmann::json::parse(test::read_text(report))["peak_memory_bytes"].get<double>();
  EXPECT_GT(peak, 20e6);
  EXPECT_LT(peak, 400e6);
}

}  // namespace
}  // namespace vertexflow
