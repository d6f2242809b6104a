// `vertexflow simplify`, `vertexflow remesh` and `vertexflow enhance --method unsharp` end to end:
// outputs, JSON, one-line errors with exit code 1, no output written on failure.
#include "raw_scan.h"
#include "test_support.h"

#include "vertexflow/io.h"
#include "vertexflow/simplify.h"
#include "vertexflow/topology.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fstream>
#include <iostream>
#include <sstream>

namespace vertexflow {
namespace {

using test::quoted_data_path;
using test::run_cli;
using test::shell_quote;

// One line on stderr, "vertexflow: error: ...", containing `text`; exit code 1; no output file.
void expect_one_line_error(const test::CommandResult& r, const std::string& text) {
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_EQ(r.err.rfind("vertexflow: error: ", 0), 0u) << r.err;
  EXPECT_NE(r.err.find(text), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
}

std::filesystem::path write_bowtie(const test::ScratchDir& dir) {
  const auto bowtie = dir.file("bowtie.obj");
  std::ofstream(bowtie) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv -1 0 0\nv 0 -1 0\nf 1 2 3\nf 1 4 5\n";
  return bowtie;
}

TEST(CliSimplify, WritesTheBudgetAndASummary) {
  test::ScratchDir dir("cli-simplify");
  const auto out = dir.file("camel.ply");
  const auto r = run_cli("simplify " + quoted_data_path("camelhead.off") + " " + shell_quote(out.string()) +
                         " --faces 3000 --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  const Mesh result = read_mesh(out);
  EXPECT_EQ(j["faces"], result.num_faces());
  EXPECT_EQ(j["vertices"], result.num_vertices());
  EXPECT_GE(result.num_faces(), 3000);
  EXPECT_LE(result.num_faces(), 3001);
  EXPECT_EQ(j["target_faces"], 3000);
  EXPECT_EQ(j["keep_boundary"], true);
  EXPECT_NE(r.err.find("simplified 22704 -> "), std::string::npos) << r.err;
  const Topology topology = build_topology(result.F, result.num_vertices());
  EXPECT_TRUE(topology.is_manifold());
  EXPECT_EQ(topology.boundary_loops.size(), 1u);

  const auto half = dir.file("half.off");
  const auto ratio =
      run_cli("--quiet simplify " + quoted_data_path("spot.obj") + " " + shell_quote(half.string()) + " --ratio 0.5");
  ASSERT_EQ(ratio.exit_code, 0) << ratio.err;
  EXPECT_TRUE(ratio.err.empty()) << ratio.err;
  EXPECT_EQ(read_mesh(half).num_faces(), 2928);
}

// --method native: the library's SimplifyMethod::Native (tests/remesh/test_simplify.cpp), same
// bytes as the library's call, and named in the summary.
TEST(CliSimplify, NativeMethodIsTheLibrarys) {
  test::ScratchDir dir("cli-simplify-native");
  const auto out = dir.file("camel.ply");
  const auto r = run_cli("--quiet simplify " + quoted_data_path("camelhead.off") + " " + shell_quote(out.string()) +
                         " --faces 3000 --method native --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out)["method"], "native");
  const Mesh camel = read_mesh(test::data_path("camelhead.off"));
  SimplifyOptions options;
  options.target_faces = 3000;
  options.method = SimplifyMethod::Native;
  const Mesh expected = simplify(camel.V, camel.F, options).mesh;
  const Mesh written = read_mesh(out);
  EXPECT_EQ(written.F, expected.F);
  EXPECT_EQ(written.V, expected.V);  // binary PLY: doubles kept
  const auto bad = run_cli("simplify " + quoted_data_path("camelhead.off") + " " +
                           shell_quote(dir.file("x.ply").string()) + " --faces 3000 --method fast");
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_NE(bad.err.find("--method"), std::string::npos) << bad.err;
}

TEST(CliSimplify, BadInputFailsCleanly) {
  test::ScratchDir dir("cli-simplify-bad");
  const auto out = dir.file("out.off");
  expect_one_line_error(
      run_cli("--quiet simplify " + quoted_data_path("spot.obj") + " " + shell_quote(out.string()) + " --ratio 0"),
      "spot.obj: simplify: the target ratio must be in (0, 1]");
  expect_one_line_error(run_cli("simplify /nonexistent/in.off " + shell_quote(out.string()) + " --faces 10"),
                        "/nonexistent/in.off: ");
  EXPECT_FALSE(std::filesystem::exists(out));
  // A usage error: neither or both budgets.
  EXPECT_NE(run_cli("simplify " + quoted_data_path("spot.obj") + " " + shell_quote(out.string())).exit_code, 0);
  EXPECT_NE(
      run_cli("simplify " + quoted_data_path("spot.obj") + " " + shell_quote(out.string()) + " --faces 10 --ratio 0.5")
          .exit_code,
      0);
  EXPECT_FALSE(std::filesystem::exists(out));
}

TEST(CliRemesh, ReportsCountAndQuality) {
  test::ScratchDir dir("cli-remesh");
  const auto out = dir.file("fertility.obj");
  const auto r = run_cli("remesh " + quoted_data_path("fertility.off") + " " + shell_quote(out.string()) +
                         " --target-vertices 1500 --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  const Mesh result = read_mesh(out);
  EXPECT_EQ(j["vertices"], result.num_vertices());
  EXPECT_EQ(j["within_tolerance"], true);
  EXPECT_LE(std::abs(result.num_vertices() - 1500), 75);
  EXPECT_GE(j["runs"].size(), 1u);
  EXPECT_GT(j["quality"]["mean"].get<double>(), 0.85);
  EXPECT_NE(r.err.find("-> " + std::to_string(result.num_vertices()) + " vertices"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("quality 2r/R: min"), std::string::npos) << r.err;
  EXPECT_EQ(build_topology(result.F, result.num_vertices()).genus(), 4);

  const auto fixed = dir.file("fixed.off");
  const auto length = run_cli("--quiet remesh " + quoted_data_path("torus.obj") + " " + shell_quote(fixed.string()) +
                              " --edge-length 0.1");
  ASSERT_EQ(length.exit_code, 0) << length.err;
  EXPECT_TRUE(length.err.empty()) << length.err;
  EXPECT_GT(read_mesh(fixed).num_vertices(), 100);
}

// A non-manifold input is remeshed and simplified through its split, with one warning line
// that names the file and says what was split, and the counts in --json.
TEST(CliRemeshAndSimplify, NonManifoldInputIsSplitWithAWarning) {
  test::ScratchDir dir("cli-remesh-non-manifold");
  const auto bowtie = write_bowtie(dir);
  const auto out = dir.file("out.off");
  for (const std::string command : {"remesh --edge-length 0.25", "simplify --faces 2"}) {
    const auto r = run_cli(command.substr(0, command.find(' ')) + " " + shell_quote(bowtie.string()) + " " +
                           shell_quote(out.string()) + command.substr(command.find(' ')) + " --json");
    ASSERT_EQ(r.exit_code, 0) << command << ": " << r.err;
    EXPECT_NE(r.err.find("vertexflow: warning: " + bowtie.string() +
                         ": the mesh is not manifold or not consistently oriented: 1 vertices split"),
              std::string::npos)
        << r.err;
    EXPECT_EQ(nlohmann::json::parse(r.out)["repairs"]["input_split_vertices"], 1) << command;
    const Mesh result = read_mesh(out);
    test::expect_clean_surface(result);
  }
}

// Issue 31: a raw scan (raw_scan.h, from bunny.off) remeshed with the pieces too small to remesh
// counted in a warning and in --json, the quality over interior and rim faces reported, and the
// result taken by enhance in every mode without a flipped face.
TEST(CliRemesh, RawScanIsRemeshedCleanAndEnhancedInEveryMode) {
  test::ScratchDir dir("cli-remesh-raw-scan");
  const auto scan = dir.file("raw.ply");
  write_mesh(scan, test::make_raw_scan(read_mesh(test::data_path("bunny.off"))).mesh);
  const auto out = dir.file("remesh.ply");
  const auto r = run_cli("remesh " + shell_quote(scan.string()) + " " + shell_quote(out.string()) +
                         " --target-vertices 6000 --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  const Index pieces = j["cleanup"]["small_pieces"];
  EXPECT_GE(pieces, 80);  // measured 105
  EXPECT_EQ(j["cleanup"]["small_pieces_kept"], false);
  EXPECT_NE(r.err.find("vertexflow: warning: " + scan.string() + ": " + std::to_string(pieces) + " pieces ("),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("too small to remesh: removed"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("interior faces"), std::string::npos) << r.err;
  EXPECT_GT(j["cleanup"]["short_loops_kept"].get<Index>(), 0);
  EXPECT_LE(j["quality_interior"]["fraction_below_0_3"].get<double>(), 0.02);
  EXPECT_TRUE(j["quality_rim"].contains("fraction_below_0_3"));
  EXPECT_EQ(j["interior_faces"].get<Index>() + j["rim_faces"].get<Index>(), j["faces"].get<Index>());
  EXPECT_EQ(j["zero_area_faces"], 0);
  EXPECT_EQ(j["non_manifold_vertices"], 0);
  EXPECT_GE(j["min_edge_length"].get<double>(), 1e-4 * j["edge_length"].get<double>());
  const Mesh result = read_mesh(out);
  test::expect_clean_surface(result);
  EXPECT_EQ(j["components"], build_topology(result.F, result.num_vertices()).num_components);

  for (const std::string& mode :
       std::vector<std::string>{"", "--density-passes 3", "--method unsharp", "--surface smooth",
                                "--reference " + shell_quote(scan.string())}) {
    const auto report = dir.file("report.json");
    const auto e =
        run_cli("--quiet enhance " + shell_quote(out.string()) + " " + shell_quote(dir.file("enhanced.ply").string()) +
                " " + mode + " --force --report " + shell_quote(report.string()));
    ASSERT_EQ(e.exit_code, 0) << mode << ": " << e.err;
    const auto rep = nlohmann::json::parse(test::read_text(report));
    EXPECT_EQ(rep["flipped_faces"], 0) << mode;
    // The input check (flow, density passes, smooth mode) does not take the remesh for decimated.
    if (rep.contains("hold")) {
      EXPECT_EQ(rep["hold"]["held"], false) << mode;
    }
    if (mode == "--surface smooth") {
      // Smooth mode brings it closer to the dense mesh: measured -11.9% (issue 31 asks for 5%).
      const auto c = run_cli("compare --json " + shell_quote(dir.file("enhanced.ply").string()) + " " +
                             shell_quote(out.string()) + " --reference " + quoted_data_path("bunny.off"));
      ASSERT_EQ(c.exit_code, 0) << c.err;
      const auto d = nlohmann::json::parse(c.out)["distance"];
      const double before = d["input_reference"]["input_to_reference"]["mean_relative"];
      const double after = d["result_reference"]["result_to_reference"]["mean_relative"];
      std::cout << "[measured] smooth mode on the raw-scan remesh: mean distance " << before << " -> " << after << "\n";
      EXPECT_LT(after, 0.95 * before);
    }
  }

  // --small-pieces keep copies them unchanged, the same count.
  std::ostringstream length;
  length.precision(17);
  length << j["edge_length"].get<double>();
  const auto keep = run_cli("--quiet remesh " + shell_quote(scan.string()) + " " + shell_quote(out.string()) +
                            " --edge-length " + length.str() + " --small-pieces keep --force --json");
  ASSERT_EQ(keep.exit_code, 0) << keep.err;
  const auto k = nlohmann::json::parse(keep.out);
  EXPECT_EQ(k["cleanup"]["small_pieces_kept"], true);
  EXPECT_EQ(k["cleanup"]["small_pieces"], pieces);
  EXPECT_EQ(k["components"].get<Index>(), j["components"].get<Index>() + pieces);
}

TEST(CliRemesh, BadInputFailsCleanly) {
  test::ScratchDir dir("cli-remesh-bad");
  const auto out = dir.file("out.off");
  expect_one_line_error(run_cli("--quiet remesh " + quoted_data_path("spot.obj") + " " + shell_quote(out.string()) +
                                " --edge-length 1e-7"),
                        "spot.obj: remesh: the edge length 1e-07 would give about");
  EXPECT_FALSE(std::filesystem::exists(out));
  EXPECT_NE(run_cli("remesh " + quoted_data_path("spot.obj") + " " + shell_quote(out.string())).exit_code, 0);
  EXPECT_NE(run_cli("remesh " + quoted_data_path("spot.obj") + " " + shell_quote(out.string()) + " --target-vertices 2")
                .exit_code,
            0);
  EXPECT_NE(run_cli("remesh " + quoted_data_path("spot.obj") + " " + shell_quote(out.string()) + " --edge-length -1")
                .exit_code,
            0);
  EXPECT_FALSE(std::filesystem::exists(out));
}

TEST(CliEnhanceUnsharp, WritesTheMeshAndTheSameReport) {
  test::ScratchDir dir("cli-enhance-unsharp");
  const auto out = dir.file("head.ply");
  const auto report = dir.file("report.json");
  const auto pins = dir.file("pins.txt");
  { std::ofstream(pins) << "3 77\n"; }
  const auto r = run_cli("enhance " + quoted_data_path("max-planck-5k.obj") + " " + shell_quote(out.string()) +
                         " --method unsharp --weight 0.5 --pin " + shell_quote(pins.string()) + " --report " +
                         shell_quote(report.string()));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Mesh input = read_mesh(test::data_path("max-planck-5k.obj"));
  const Mesh result = read_mesh(out);
  ASSERT_EQ(result.F, input.F);
  EXPECT_EQ(result.V.row(3), input.V.row(3));
  EXPECT_EQ(result.V.row(77), input.V.row(77));
  EXPECT_GT((result.V - input.V).rowwise().norm().maxCoeff(), 0.0);
  const auto j = nlohmann::json::parse(test::read_text(report));
  EXPECT_EQ(j["method"], "unsharp");
  EXPECT_EQ(j["options"]["weight"], 0.5);
  EXPECT_EQ(j["options"]["smoothing_iterations"], 5);
  EXPECT_EQ(j["options"]["pinned"], 2);
  // The flow's metrics, measured the same way.
  for (const char* key : {"flipped_faces", "degenerate_faces", "quality_input", "quality_result",
                          "displacement_edge_lengths", "redistribution_rho", "edge_error_cv", "volume_change_percent"})
    EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_FALSE(j.contains("solver"));
  EXPECT_GT(j["displacement_edge_lengths"]["max"].get<double>(), 0.0);

  // The default method is recorded as the flow.
  const auto flow_report = dir.file("flow.json");
  const auto flow =
      run_cli("--quiet enhance " + quoted_data_path("spot.obj") + " " + shell_quote(dir.file("spot.ply").string()) +
              " --report " + shell_quote(flow_report.string()));
  ASSERT_EQ(flow.exit_code, 0) << flow.err;
  EXPECT_EQ(nlohmann::json::parse(test::read_text(flow_report))["method"], "flow");
}

TEST(CliEnhanceUnsharp, OptionsOfTheOtherMethodAreRefused) {
  test::ScratchDir dir("cli-enhance-unsharp-bad");
  const auto out = dir.file("out.ply");
  expect_one_line_error(
      run_cli("enhance " + quoted_data_path("spot.obj") + " " + shell_quote(out.string()) + " --weight 0.5"),
      "--weight does not apply to the paper's flow");
  expect_one_line_error(run_cli("enhance " + quoted_data_path("spot.obj") + " " + shell_quote(out.string()) +
                                " --method unsharp --lambda 2"),
                        "--lambda does not apply to --method unsharp");
  expect_one_line_error(run_cli("--quiet enhance " + shell_quote(write_bowtie(dir).string()) + " " +
                                shell_quote(out.string()) + " --method unsharp --strict"),
                        "bowtie.obj: unsharp mask: the mesh is not manifold");
  EXPECT_FALSE(std::filesystem::exists(out));
  // Without --strict the bowtie is smoothed as its manifold split, with one warning line.
  const auto report = dir.file("bowtie.json");
  const auto split = run_cli("enhance " + shell_quote(write_bowtie(dir).string()) + " " + shell_quote(out.string()) +
                             " --method unsharp --report " + shell_quote(report.string()));
  ASSERT_EQ(split.exit_code, 0) << split.err;
  EXPECT_NE(split.err.find("bowtie.obj: the mesh is not manifold or not consistently oriented: 1 vertices held"),
            std::string::npos)
      << split.err;
  EXPECT_EQ(nlohmann::json::parse(test::read_text(report))["non_manifold"]["held_vertices"], 1);
  std::filesystem::remove(out);
  EXPECT_NE(run_cli("enhance " + quoted_data_path("spot.obj") + " " + shell_quote(out.string()) + " --method laplace")
                .exit_code,
            0);
  EXPECT_FALSE(std::filesystem::exists(out));
}

}  // namespace
}  // namespace vertexflow
