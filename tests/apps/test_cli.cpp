// The `vertexflow` executable end to end: output, JSON, exit codes, one-line errors.
#include "test_support.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

namespace vertexflow {
namespace {

using test::run_cli;
using test::shell_quote;

std::string data(const std::string& name) { return shell_quote(test::data_path(name).string()); }

TEST(CliInfo, PrintsTheSummary) {
  const auto r = run_cli("info " + data("torus.obj"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("vertices              2304"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("genus                 1"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("quality 2r/R"), std::string::npos) << r.out;
  EXPECT_TRUE(r.err.empty()) << r.err;
}

TEST(CliInfo, JsonHasTheSameNumbers) {
  const auto r = run_cli("info --json " + data("hemisphere.off"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["vertices"], 1861);
  EXPECT_EQ(j["faces"], 3600);
  EXPECT_EQ(j["boundary_loops"], 1);
  EXPECT_EQ(j["components"], 1);
  EXPECT_EQ(j["genus"], 0);
  EXPECT_EQ(j["manifold"], true);
  EXPECT_EQ(j["closed"], false);
  EXPECT_EQ(j["euler_characteristic"], 1);
  EXPECT_GT(j["diagonal"].get<double>(), 0.0);
  EXPECT_LE(j["edge_length"]["min"].get<double>(), j["edge_length"]["mean"].get<double>());
  EXPECT_LE(j["edge_length"]["mean"].get<double>(), j["edge_length"]["max"].get<double>());
  EXPECT_EQ(j["quality"]["histogram"].size(), 10u);
  EXPECT_EQ(j["read"]["format"], "OFF (ASCII)");
}

TEST(CliInfo, NonManifoldIsReported) {
  const auto r = run_cli("info --json " + data("suzanne.obj"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["components"], 3);
  EXPECT_EQ(j["boundary_loops"], 4);
  // Warnings about triangulation go to stderr, one line each, and not with --quiet.
  EXPECT_NE(r.err.find("468 polygons triangulated"), std::string::npos) << r.err;
  EXPECT_TRUE(run_cli("--quiet info " + data("suzanne.obj")).err.empty());
}

TEST(CliInfo, MissingFileIsOneLineErrorAndExitCode1) {
  const auto r = run_cli("info /nonexistent/mesh.off");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(r.err.rfind("vertexflow: error: /nonexistent/mesh.off: ", 0), 0u) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_TRUE(r.out.empty());
}

TEST(Cli, UsageErrorsFail) {
  EXPECT_NE(run_cli("").exit_code, 0);
  EXPECT_NE(run_cli("info").exit_code, 0);
  EXPECT_NE(run_cli("frobnicate x.off").exit_code, 0);
  const auto version = run_cli("--version");
  EXPECT_EQ(version.exit_code, 0);
  EXPECT_NE(version.out.find("vertexflow"), std::string::npos);
}

}  // namespace
}  // namespace vertexflow
