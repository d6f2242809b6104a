// `vertexflow report` and `vertexflow enhance --html` end to end: files written, inputs never
// overwritten, one-line errors.
#include "page_data.h"
#include "test_support.h"

#include "vertexflow/flow.h"
#include "vertexflow/io.h"
#include "vertexflow/report_json.h"
#include "vertexflow/unsharp.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <set>
#include <string>

namespace vertexflow {
namespace {

using test::run_cli;
using test::shell_quote;

std::string q(const std::filesystem::path& path) {
  return test::quoted(path);
}

// fandisk at the defaults: mean displacement 0.46 mean edge lengths and rho 0.027 -> 0.498
// measured (tests/flow's FlowOnMesh bounds): the flow ran, it was not replaced by the identity.
void expect_the_flow_moved_fandisk(const nlohmann::json& report) {
  EXPECT_GT(report["displacement_edge_lengths"]["mean"].get<double>(), 0.18);
  EXPECT_GT(report["redistribution_rho"]["result"].get<double>(),
            report["redistribution_rho"]["input"].get<double>() + 0.19);
}

TEST(CliReport, EnhanceWritesTheHtmlReportWithTheJsonMetrics) {
  test::ScratchDir dir("cli-report-enhance");
  const auto out = dir.file("out.ply"), json = dir.file("r.json"), html = dir.file("r.html");
  const auto r = run_cli("enhance " + q(test::data_path("fandisk.off")) + " " + q(out) + " --report " + q(json) +
                         " --html " + q(html));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string page = test::read_text(html);
  ASSERT_FALSE(page.empty());
  // The metrics table holds the --report JSON (timings, options and all).
  const auto report = nlohmann::json::parse(test::read_text(json));
  const auto data = test::page_data(page);
  EXPECT_EQ(data["metrics"], report);
  EXPECT_FALSE(data["display"].contains("result_indices")) << "the flow keeps the input's faces";
  expect_the_flow_moved_fandisk(report);
  EXPECT_EQ(data["labels"]["input"], "fandisk.off");
  EXPECT_EQ(data["labels"]["result"], "out.ply");
  EXPECT_NE(r.err.find("HTML report written to"), std::string::npos) << r.err;
}

// spot.obj's texture coordinates reach the page on both sides, the result's re-sampled by
// enhance, for the checker view.
TEST(CliReport, EnhanceReportOfATexturedMeshHasTheCheckerView) {
  test::ScratchDir dir("cli-report-spot");
  const auto out = dir.file("out.obj"), html = dir.file("r.html");
  const auto r = run_cli("--quiet enhance " + q(test::data_path("spot.obj")) + " " + q(out) + " --html " + q(html));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto data = test::page_data(test::read_text(html));
  ASSERT_TRUE(data.contains("texture"));
  const std::size_t faces = data["display"]["faces"];
  const auto input_uv = test::decode_array<float>(data["input"]["uv"]);
  const auto result_uv = test::decode_array<float>(data["result"]["uv"]);
  ASSERT_EQ(input_uv.size(), 6 * faces);
  ASSERT_EQ(result_uv.size(), 6 * faces);
  EXPECT_NE(input_uv, result_uv) << "the result's coordinates are the input's: not re-sampled?";
  // Re-sampled, not scrambled: every corner stays near its input value (0.043 measured, in
  // a [0, 1] chart).
  double worst = 0;
  for (std::size_t i = 0; i < input_uv.size(); ++i)
    worst = std::max(worst, double(std::abs(input_uv[i] - result_uv[i])));
  EXPECT_LT(worst, 0.1);
}

std::set<std::string> keys(const nlohmann::json& j) {
  std::set<std::string> out;
  for (const auto& [key, value] : j.items()) out.insert(key);
  return out;
}

// The metrics both methods' reports hold (flow_metrics).
const std::set<std::string> kMetricKeys = {"abs_mean_curvature_p95",
                                           "degenerate_faces",
                                           "displacement_edge_lengths",
                                           "drift_edge_lengths",
                                           "edge_error_cv",
                                           "edge_error_max_over_mean",
                                           "faces",
                                           "flipped_faces",
                                           "quality_input",
                                           "quality_result",
                                           "redistribution_rho",
                                           "vertices",
                                           "volume_change_percent"};

std::set<std::string> with_metrics(std::set<std::string> keys) {
  keys.insert(kMetricKeys.begin(), kMetricKeys.end());
  return keys;
}

// The options section is to_json(FlowOptions) (report_json.h) of the options the command line
// gave, and the solver and guard sections to_json(FlowReport) of the same flow run here.
TEST(CliReport, EnhanceReportHoldsTheFlowsOptionsAndReport) {
  test::ScratchDir dir("cli-report-flow-json");
  const auto input = test::data_path("fandisk.off");
  const auto out = dir.file("out.ply"), json = dir.file("r.json");
  const auto r = run_cli("--quiet enhance " + q(input) + " " + q(out) + " --report " + q(json) +
                         " --lambda 2 --mu 0.25 --fairness zero --min-quality 0.2 --feature-angle 30 --free-boundary "
                         "--no-projection");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto report = nlohmann::json::parse(test::read_text(json));
  FlowOptions options;
  options.weights.lambda = 2;
  options.weights.mu = 0.25;
  options.weights.fairness_target = FairnessTarget::Zero;
  options.guard.min_quality = 0.2;
  options.feature_angle = 30;
  options.constraints.fix_boundary = false;
  options.project_to_input = false;
  EXPECT_EQ(report["options"], nlohmann::json(options));
  for (const char* key : {"solver", "solver_tolerance", "max_halvings", "curvature"})
    EXPECT_TRUE(report["options"].contains(key)) << key;
  EXPECT_EQ(keys(report), with_metrics({"input", "output", "method", "options", "solver", "guard", "non_manifold",
                                        "seconds", "provenance", "peak_memory_bytes", "hold"}));
  EXPECT_FALSE(report["hold"]["held"]);  // fandisk is neither decimated nor a control mesh (input_check.h)
  EXPECT_EQ(report["provenance"], "vertexflow enhance --surface input");  // the line added to OUT (provenance.h)
  EXPECT_EQ(keys(report["seconds"]), (std::set<std::string>{"read", "curvature", "assembly", "solve", "factorization",
                                                            "projection", "guard", "density", "set_up", "write"}));
  const Mesh mesh = read_mesh(input);
  const FlowResult flow = vertex_flow(mesh.V, mesh.F, options);
  const nlohmann::json expected = flow.report;
  EXPECT_EQ(report["solver"], expected["solver"]);
  EXPECT_EQ(report["guard"], expected["guard"]);
  EXPECT_EQ(read_mesh(out).V, flow.V);
  EXPECT_GT(report["displacement_edge_lengths"]["mean"].get<double>(), 0.1);  // measured 0.40 with these options
}

// The baseline's report has its own sections, the same keys as before it had a path of its own:
// its options, its fixed vertices and its phases' seconds; no solver or guard.
TEST(CliReport, UnsharpReportHoldsItsOwnSections) {
  test::ScratchDir dir("cli-report-unsharp-json");
  const auto input = test::data_path("fandisk.off");
  const auto out = dir.file("out.ply"), json = dir.file("r.json"), html = dir.file("r.html");
  const auto r = run_cli("--quiet enhance " + q(input) + " " + q(out) +
                         " --method unsharp --weight 0.5 "
                         "--smoothing-iterations 3 --free-boundary --report " +
                         q(json) + " --html " + q(html));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto report = nlohmann::json::parse(test::read_text(json));
  UnsharpOptions options;
  options.weight = 0.5;
  options.smoothing_iterations = 3;
  options.constraints.fix_boundary = false;
  EXPECT_EQ(report["options"], nlohmann::json(options));
  EXPECT_EQ(report["method"], "unsharp");
  EXPECT_EQ(keys(report), with_metrics({"input", "output", "method", "options", "fixed_vertices", "non_manifold",
                                        "seconds", "provenance", "peak_memory_bytes"}));
  EXPECT_EQ(report["provenance"], "vertexflow enhance --method unsharp");
  EXPECT_EQ(keys(report["seconds"]), (std::set<std::string>{"read", "unsharp", "write"}));
  const Mesh mesh = read_mesh(input);
  const UnsharpResult unsharp = unsharp_mask(mesh.V, mesh.F, options);
  EXPECT_EQ(report["fixed_vertices"], unsharp.fixed_vertices);
  EXPECT_EQ(read_mesh(out).V, unsharp.V);
  EXPECT_FALSE(test::read_text(html).empty());
}

TEST(CliReport, ReportOfAnExistingResult) {
  test::ScratchDir dir("cli-report");
  const auto input = test::data_path("fandisk.off");
  const auto out = dir.file("out.ply"), json = dir.file("metrics.json"), html = dir.file("report.html");
  ASSERT_EQ(
      run_cli("--quiet enhance " + q(input) + " " + q(out) + " --report " + q(dir.file("enhance.json"))).exit_code, 0);
  const auto r = run_cli("--quiet report " + q(input) + " " + q(out) + " " + q(html) + " --json-report " + q(json));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(r.err.empty()) << r.err;
  EXPECT_FALSE(test::read_text(html).empty());
  // The same metrics as enhance's own report (everything it measures, not the timings).
  const auto metrics = nlohmann::json::parse(test::read_text(json));
  const auto enhance = nlohmann::json::parse(test::read_text(dir.file("enhance.json")));
  expect_the_flow_moved_fandisk(enhance);
  for (const char* key :
       {"vertices", "faces", "flipped_faces", "degenerate_faces", "quality_input", "quality_result",
        "redistribution_rho", "edge_error_cv", "displacement_edge_lengths", "volume_change_percent"}) {
    ASSERT_TRUE(metrics.contains(key)) << key;
    EXPECT_EQ(metrics[key].dump().substr(0, 40), enhance[key].dump().substr(0, 40)) << key;
  }
}

TEST(CliReport, DecimationLimitOption) {
  test::ScratchDir dir("cli-report-decimate");
  const auto mesh = test::data_path("fandisk.off");
  const auto html = dir.file("r.html");
  // The input compared with itself: a valid (if dull) report.
  const auto r = run_cli("--quiet report " + q(mesh) + " " + q(mesh) + " " + q(html) + " --max-display-faces 2000");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(test::read_text(html).find("decimation for display"), std::string::npos);
  EXPECT_NE(run_cli("report " + q(mesh) + " " + q(mesh) + " " + q(html) + " --max-display-faces 0").exit_code, 0);
}

TEST(CliReport, NeverOverwritesAnInputAndFailsOnOneLine) {
  test::ScratchDir dir("cli-report-refuse");
  const auto copy = dir.file("in.off");
  std::filesystem::copy_file(test::data_path("fandisk.off"), copy);
  const std::string before = test::read_text(copy);
  for (const std::string& args :
       {"report " + q(copy) + " " + q(copy) + " " + q(copy),
        "report " + q(copy) + " " + q(test::data_path("fandisk.off")) + " " + q(copy),
        "report " + q(test::data_path("fandisk.off")) + " " + q(copy) + " " + q(copy),
        "report " + q(copy) + " " + q(copy) + " " + q(dir.file("r.html")) + " --json-report " + q(copy),
        "enhance " + q(copy) + " " + q(dir.file("o.ply")) + " --html " + q(copy),
        // --force lets enhance replace its input mesh, never by a report.
        "enhance " + q(copy) + " " + q(dir.file("o.ply")) + " --html " + q(copy) + " --force"}) {
    const auto r = run_cli(args);
    EXPECT_EQ(r.exit_code, 1) << args;
    EXPECT_NE(r.err.find("refusing to overwrite"), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  }
  EXPECT_EQ(test::read_text(copy), before);
  // The HTML report and the JSON report must be different files.
  const auto same = run_cli("report " + q(copy) + " " + q(copy) + " " + q(dir.file("r.html")) + " --json-report " +
                            q(dir.file("r.html")));
  EXPECT_EQ(same.exit_code, 1);
  EXPECT_NE(same.err.find("would overwrite another output"), std::string::npos) << same.err;
  EXPECT_FALSE(std::filesystem::exists(dir.file("r.html")));
}

// The display's faces of the result in a page: its own when it has them, else the input's.
Faces result_faces_on_page(const nlohmann::json& data) {
  const auto indices = test::decode_array<std::uint32_t>(
      data["display"].contains("result_indices") ? data["display"]["result_indices"] : data["display"]["indices"]);
  Faces F(static_cast<Index>(indices.size() / 3), 3);
  for (std::size_t i = 0; i < indices.size(); ++i) F(static_cast<Index>(i / 3), static_cast<int>(i % 3)) = indices[i];
  return F;
}

// Edge flips give the result faces of its own (same counts): `enhance --html` and `report` show
// it on them, and measure it as enhance's report does.
TEST(CliReport, EdgeFlipResultsAreReported) {
  test::ScratchDir dir("cli-report-edge-flips");
  const auto input = test::data_path("fandisk.off");
  const auto out = dir.file("out.ply"), json = dir.file("r.json"), html = dir.file("r.html");
  const auto r = run_cli("--quiet enhance " + q(input) + " " + q(out) + " --edge-flips --report " + q(json) +
                         " --html " + q(html));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Mesh mesh = read_mesh(input), result = read_mesh(out);
  ASSERT_EQ(result.num_faces(), mesh.num_faces());
  ASSERT_NE(result.F, mesh.F) << "no edge flipped: the test tells nothing";
  const auto report = nlohmann::json::parse(test::read_text(json));
  const auto data = test::page_data(test::read_text(html));
  EXPECT_EQ(data["metrics"], report);
  EXPECT_EQ(result_faces_on_page(data), result.F);
  EXPECT_EQ(data["display"]["result_faces"], result.num_faces());
  EXPECT_EQ(data["histograms"]["result"], report["quality_result"]["histogram"]);

  // `report` of the same pair: accepted, the same page and metrics (but for the timings and the
  // method's sections, which only enhance knows).
  const auto page = dir.file("again.html"), metrics_file = dir.file("again.json");
  const auto again =
      run_cli("--quiet report " + q(input) + " " + q(out) + " " + q(page) + " --json-report " + q(metrics_file));
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_TRUE(again.err.empty()) << again.err;
  const auto metrics = nlohmann::json::parse(test::read_text(metrics_file));
  for (const char* key : {"vertices", "faces", "flipped_faces", "degenerate_faces", "quality_input", "quality_result",
                          "redistribution_rho", "edge_error_cv", "displacement_edge_lengths", "volume_change_percent"})
    EXPECT_EQ(metrics[key], report[key]) << key;
  auto page_data = test::page_data(test::read_text(page)), enhance_data = data;
  page_data.erase("metrics");
  enhance_data.erase("metrics");
  EXPECT_TRUE(page_data == enhance_data) << "the pages differ beyond their metrics";
}

TEST(CliReport, ResultOfAnotherMeshIsAnError) {
  test::ScratchDir dir("cli-report-mismatch");
  // Another vertex count, and the input's vertices with a face fewer: neither is a result of it.
  Mesh fewer = read_mesh(test::data_path("fandisk.off"));
  fewer.F.conservativeResize(fewer.F.rows() - 1, 3);
  write_mesh(dir.file("fewer.off"), fewer);
  ASSERT_EQ(read_mesh(dir.file("fewer.off")).num_vertices(), fewer.num_vertices());
  for (const std::filesystem::path& other : {test::data_path("torus.obj"), dir.file("fewer.off")}) {
    const auto r =
        run_cli("report " + q(test::data_path("fandisk.off")) + " " + q(other) + " " + q(dir.file("r.html")));
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_EQ(r.err.rfind("vertexflow: error: " + other.string() + ": not a result of " +
                              test::data_path("fandisk.off").string() + " (",
                          0),
              0u)
        << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_FALSE(std::filesystem::exists(dir.file("r.html")));
  }
}

}  // namespace
}  // namespace vertexflow
