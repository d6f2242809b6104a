// Output paths of every subcommand are checked before any work: a bad path fails at once, on
// one line, and no other output is written.
#include "test_support.h"

#include "vertexflow/io.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <functional>
#include <vector>

#include <fcntl.h>
#include <unistd.h>

namespace vertexflow {
namespace {

using test::run_cli;
using test::shell_quote;

std::string q(const std::filesystem::path& path) { return test::quoted(path); }

std::vector<std::string> entries(const std::filesystem::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : std::filesystem::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

// A directory in which no file can be created. chmod 0555 does not stop root (or any process
// with CAP_DAC_OVERRIDE), so when a probe shows that it does not, /proc stands in: nobody can
// create a file there.
std::filesystem::path unwritable_dir(const test::ScratchDir& dir) {
  const auto ro = dir.file("read-only");
  std::filesystem::create_directory(ro);
  std::filesystem::permissions(ro, std::filesystem::perms::owner_read | std::filesystem::perms::owner_exec |
                                       std::filesystem::perms::group_read | std::filesystem::perms::group_exec |
                                       std::filesystem::perms::others_read | std::filesystem::perms::others_exec);
  const auto probe = ro / "probe";
  const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL, 0644);
  if (fd < 0) return ro;
  ::close(fd);
  std::filesystem::remove(probe);
  return "/proc";
}

struct BadPath {
  std::string what;
  std::filesystem::path dir;
};

// The ways an output's directory can refuse a new file.
std::vector<BadPath> bad_dirs(const test::ScratchDir& dir) {
  const auto regular = dir.file("regular-file");
  { std::ofstream(regular) << "not a directory\n"; }
  return {{"missing directory", dir.file("missing")},
          {"parent is a regular file", regular},
          {"read-only directory", unwritable_dir(dir)}};
}

// One invocation with one bad output; `good` are the other outputs, which must not be written.
struct PreflightCase {
  std::string name;
  std::string extension;  // of the bad output
  std::function<std::string(const std::string& input, const std::string& bad, const std::filesystem::path& good_dir)>
      arguments;
  std::vector<std::string> good;  // file names in good_dir
};

std::vector<PreflightCase> preflight_cases() {
  return {
      {"curvature", ".ply", [](auto& in, auto& bad, auto&) { return "curvature " + in + " " + bad; }, {}},
      {"enhance", ".ply", [](auto& in, auto& bad, auto&) { return "enhance " + in + " " + bad; }, {}},
      {"enhance --report",
       ".json",
       [](auto& in, auto& bad, auto& good) {
         return "enhance " + in + " " + q(good / "out.ply") + " --html " + q(good / "r.html") + " --report " + bad;
       },
       {"out.ply", "r.html"}},
      {"enhance --html",
       ".html",
       [](auto& in, auto& bad, auto& good) {
         return "enhance " + in + " " + q(good / "out.ply") + " --report " + q(good / "r.json") + " --html " + bad;
       },
       {"out.ply", "r.json"}},
      {"simplify",
       ".off",
       [](auto& in, auto& bad, auto&) { return "simplify " + in + " " + bad + " --ratio 0.5"; },
       {}},
      {"remesh",
       ".obj",
       [](auto& in, auto& bad, auto&) { return "remesh " + in + " " + bad + " --target-vertices 500"; },
       {}},
      {"render", ".png", [](auto& in, auto& bad, auto&) { return "render " + in + " " + bad + " --size 64x48"; }, {}},
      {"report", ".html", [](auto& in, auto& bad, auto&) { return "report " + in + " " + in + " " + bad; }, {}},
      {"report --json-report",
       ".json",
       [](auto& in, auto& bad, auto& good) {
         return "report " + in + " " + in + " " + q(good / "r.html") + " --json-report " + bad;
       },
       {"r.html"}},
  };
}

TEST(CliOutputs, BadOutputDirectoryFailsFirstOnOneLineAndWritesNothing) {
  test::ScratchDir dir("cli-preflight");
  const auto good_dir = dir.file("good");
  std::filesystem::create_directory(good_dir);
  // An input that cannot be read: an output error naming the output, not this file, shows the
  // outputs were checked before the input was even read, let alone processed.
  const auto garbage = dir.file("garbage.off");
  { std::ofstream(garbage) << "OFF\n3 1 0\nnot a number\n"; }
  const std::vector<BadPath> bad = bad_dirs(dir);
  for (const PreflightCase& c : preflight_cases()) {
    for (const BadPath& b : bad) {
      // With other outputs, also a good input: they must not be written although the
      // computation would succeed.
      std::vector<std::filesystem::path> inputs = {garbage};
      if (!c.good.empty()) inputs.push_back(test::data_path("fandisk.off"));
      for (const auto& input : inputs) {
        const auto bad_path = b.dir / ("out" + c.extension);
        const std::string args = "--quiet " + c.arguments(q(input), q(bad_path), good_dir);
        const auto r = run_cli(args);
        SCOPED_TRACE(c.name + ", " + b.what + ": " + args);
        EXPECT_EQ(r.exit_code, 1);
        EXPECT_EQ(r.err.rfind("vertexflow: error: " + bad_path.string() + ": ", 0), 0u) << r.err;
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
        EXPECT_TRUE(r.out.empty()) << r.out;
        EXPECT_FALSE(std::filesystem::exists(bad_path));
        EXPECT_TRUE(entries(good_dir).empty()) << "other outputs were written";
        if (b.dir.string() != "/proc") {
          EXPECT_TRUE(!std::filesystem::is_directory(b.dir) || entries(b.dir).empty());
        }
      }
    }
  }
}

TEST(CliOutputs, AGoodRunAfterwardsWritesEveryOutput) {
  // The same invocations with good paths succeed: the preflight refuses only what it should.
  test::ScratchDir dir("cli-preflight-good");
  const auto good_dir = dir.file("good");
  std::filesystem::create_directory(good_dir);
  for (const PreflightCase& c : preflight_cases()) {
    if (c.name == "remesh" || c.name == "render") continue;  // slow, and covered by their own tests
    std::filesystem::remove_all(good_dir);
    std::filesystem::create_directory(good_dir);
    const auto out = good_dir / ("out-main" + c.extension);
    const std::string args = "--quiet " + c.arguments(q(test::data_path("fandisk.off")), q(out), good_dir);
    SCOPED_TRACE(c.name + ": " + args);
    const auto r = run_cli(args);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_TRUE(std::filesystem::exists(out));
    for (const std::string& name : c.good) EXPECT_TRUE(std::filesystem::exists(good_dir / name)) << name;
    EXPECT_EQ(entries(good_dir).size(), c.good.size() + 1);  // no temporary files either
  }
}

TEST(CliOutputs, AReportNeverReplacesTheInputEvenWithForce) {
  test::ScratchDir dir("cli-preflight-force");
  const auto copy = dir.file("in.off");
  std::filesystem::copy_file(test::data_path("fandisk.off"), copy);
  const std::string before = test::read_text(copy);
  const auto r = run_cli("enhance " + q(copy) + " " + q(dir.file("out.ply")) + " --report " + q(copy) + " --force");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("refusing to overwrite"), std::string::npos) << r.err;
  EXPECT_EQ(test::read_text(copy), before);
  EXPECT_FALSE(std::filesystem::exists(dir.file("out.ply")));
}

TEST(CliOutputs, TwoOutputsOnOneFileAreRefusedUnderAnySpelling) {
  test::ScratchDir dir("cli-preflight-same");
  const auto out = dir.file("out.ply");
  const std::string spelled = (dir.path() / "sub" / ".." / "out.ply").string();
  std::filesystem::create_directory(dir.file("sub"));
  const auto r =
      run_cli("enhance " + test::quoted_data_path("fandisk.off") + " " + q(out) + " --report " + shell_quote(spelled));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("would overwrite another output"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(out));
}

}  // namespace
}  // namespace vertexflow
