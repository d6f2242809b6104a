// `vertexflow enhance` on inputs whose vertices lie off the true surface (issue 30,
// input_check.h): the paper's flow and smooth mode hold a decimated input or a subdivision
// control mesh with one warning line naming the file, the reason and `--reference DENSE`, and
// the report's "hold" section; --assume-on-surface runs them anyway.
#include "test_support.h"

#include "vertexflow/io.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <string>
#include <vector>

namespace vertexflow {
namespace {

// The lines of stderr that warn about a hold (suzanne also gets the reader's "polygons
// triangulated" and the PLY writer's warnings).
std::vector<std::string> warning_lines(const std::string& err) {
  std::vector<std::string> lines;
  std::size_t begin = 0;
  while (begin < err.size()) {
    const std::size_t end = std::min(err.find('\n', begin), err.size());
    const std::string line = err.substr(begin, end - begin);
    if (line.find("warning:") != std::string::npos && line.find("held every vertex") != std::string::npos)
      lines.push_back(line);
    begin = end + 1;
  }
  return lines;
}

TEST(CliHold, WarnsInOneLineAndTheFlagRunsAnyway) {
  test::ScratchDir dir("cli-hold");
  const auto out = dir.file("out.ply"), report = dir.file("report.json");
  const Mesh suzanne = read_mesh(test::data_path("suzanne.obj"));
  for (const std::string mode : {"", " --surface smooth"}) {
    const auto held = test::run_cli("enhance " + test::quoted_data_path("suzanne.obj") + " " + test::quoted(out) +
                                    mode + " --report " + test::quoted(report));
    ASSERT_EQ(held.exit_code, 0) << held.err;
    const std::vector<std::string> lines = warning_lines(held.err);
    ASSERT_EQ(lines.size(), 1u) << held.err;
    EXPECT_NE(lines[0].find("suzanne.obj: "), std::string::npos) << lines[0];
    EXPECT_NE(lines[0].find("subdivision control mesh"), std::string::npos) << lines[0];
    EXPECT_NE(lines[0].find("--reference DENSE"), std::string::npos) << lines[0];
    EXPECT_NE(lines[0].find("--assume-on-surface"), std::string::npos) << lines[0];
    EXPECT_EQ(read_mesh(out).V, suzanne.V) << mode;
    const nlohmann::json j = nlohmann::json::parse(test::read_text(report));
    EXPECT_TRUE(j["hold"]["held"]) << mode;
    EXPECT_EQ(j["hold"]["reason"], "subdivision control mesh");
    EXPECT_GT(j["hold"]["sharp_edge_fraction"].get<double>(), 0.08);  // measured 0.290

    const auto assumed = test::run_cli("enhance " + test::quoted_data_path("suzanne.obj") + " " + test::quoted(out) +
                                       mode + " --assume-on-surface --report " + test::quoted(report));
    ASSERT_EQ(assumed.exit_code, 0) << assumed.err;
    EXPECT_TRUE(warning_lines(assumed.err).empty()) << assumed.err;
    EXPECT_NE(read_mesh(out).V, suzanne.V) << mode;
    const nlohmann::json a = nlohmann::json::parse(test::read_text(report));
    EXPECT_FALSE(a["hold"]["held"]);
    EXPECT_EQ(a["hold"]["reason"], "subdivision control mesh");
    EXPECT_TRUE(a["hold"]["assume_on_surface"]);
  }

  // A QEM simplification, with density passes: held as decimated.
  const auto decimated = dir.file("spot_10.ply");
  ASSERT_EQ(test::run_cli("--quiet simplify " + test::quoted_data_path("spot.obj") + " " + test::quoted(decimated) +
                          " --ratio 0.1")
                .exit_code,
            0);
  const auto held =
      test::run_cli("enhance " + test::quoted(decimated) + " " + test::quoted(out) + " --density-passes 5");
  ASSERT_EQ(held.exit_code, 0) << held.err;
  const std::vector<std::string> lines = warning_lines(held.err);
  ASSERT_EQ(lines.size(), 1u) << held.err;
  EXPECT_NE(lines[0].find("spot_10.ply: "), std::string::npos) << lines[0];
  EXPECT_NE(lines[0].find("decimated"), std::string::npos) << lines[0];
  EXPECT_EQ(read_mesh(out).V, read_mesh(decimated).V);
  EXPECT_NE(read_mesh(out).comments.back().find("(held: decimated)"), std::string::npos);

  // The unsharp mask and reference mode do not assume the vertices on the surface: the flag is
  // refused there, in one line.
  for (const std::string& other :
       {std::string(" --method unsharp"), " --reference " + test::quoted_data_path("spot.obj")}) {
    const auto refused = test::run_cli("enhance " + test::quoted(decimated) + " " + test::quoted(dir.file("x.ply")) +
                                       other + " --assume-on-surface");
    EXPECT_EQ(refused.exit_code, 1) << other;
    EXPECT_EQ(std::count(refused.err.begin(), refused.err.end(), '\n'), 1) << refused.err;
    EXPECT_NE(refused.err.find("--assume-on-surface"), std::string::npos) << refused.err;
  }
}

}  // namespace
}  // namespace vertexflow
