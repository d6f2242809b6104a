// The CLI under an address-space limit (`ulimit -v`): every run ends, with exit 0 or with exit 1
// and one error line. Issue 12: OpenBLAS's pthread build started its threads as it was loaded,
// and under the limit they retried their buffers forever (the process never exited) or raised
// SIGINT (exit 130); CHOLMOD's out-of-memory was reported as "not positive definite".
#include "test_support.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <string>

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
    // `timeout` is the watchdog: a hang shows as exit 124, not as a stuck test.
    const auto r = test::run_command("ulimit -v " + std::to_string(limit_mb * 1024) + " && timeout 60 " +
                                     test::shell_quote(VERTEXFLOW_CLI) + " enhance " +
                                     test::quoted_data_path("sphere_low.off") + " " + out + " --force");
    if (r.exit_code == 127 && r.err.find("error while loading shared libraries") != std::string::npos)
      continue;  // the loader, before any code of ours runs
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
  // 25 MB steps keep a refusal in range on a machine whose libraries map more or less).
  EXPECT_GT(succeeded, 0);
  EXPECT_GT(refused, 0);
#endif
}

}  // namespace
}  // namespace vertexflow
