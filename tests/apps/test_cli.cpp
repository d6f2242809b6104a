// The `vertexflow` executable end to end: output, JSON, exit codes, one-line errors.
#include "test_support.h"

#include "vertexflow/io.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <regex>
#include <sstream>

#include <sys/stat.h>

namespace vertexflow {
namespace {

using test::quoted_data_path;
using test::run_cli;
using test::shell_quote;

// Shell-quoted path of a bundled mesh.

TEST(CliInfo, PrintsTheSummary) {
  const auto r = run_cli("info " + quoted_data_path("torus.obj"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("vertices              2304"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("genus                 1"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("quality 2r/R"), std::string::npos) << r.out;
  EXPECT_TRUE(r.err.empty()) << r.err;
}

TEST(CliInfo, JsonHasTheSameNumbers) {
  const auto r = run_cli("info --json " + quoted_data_path("hemisphere.off"));
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

TEST(CliInfo, PolygonMeshWarningsAndTopology) {
  const auto r = run_cli("info --json " + quoted_data_path("suzanne.obj"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["components"], 3);
  EXPECT_EQ(j["boundary_loops"], 4);
  // Warnings about triangulation go to stderr, one line each, and not with --quiet.
  EXPECT_NE(r.err.find("468 polygons triangulated"), std::string::npos) << r.err;
  EXPECT_TRUE(run_cli("--quiet info " + quoted_data_path("suzanne.obj")).err.empty());
}

TEST(CliInfo, MissingFileIsOneLineErrorAndExitCode1) {
  const auto r = run_cli("info /nonexistent/mesh.off");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(r.err.rfind("vertexflow: error: /nonexistent/mesh.off: ", 0), 0u) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_TRUE(r.out.empty());
}

// Nothing is dropped without a word (issue 28): enhance writes spot's texture coordinates to OBJ
// and says what STL cannot hold; remesh names what it does not carry.
TEST(CliAttributes, EnhanceCarriesThemAndEveryDropIsNamed) {
  test::ScratchDir dir("cli-attributes");
  const auto obj = run_cli("enhance " + quoted_data_path("spot.obj") + " " + test::quoted(dir.file("out.obj")));
  ASSERT_EQ(obj.exit_code, 0) << obj.err;
  EXPECT_EQ(obj.err.find("warning"), std::string::npos) << obj.err;
  const Mesh out = read_mesh(dir.file("out.obj"));
  const Mesh spot = read_mesh(test::data_path("spot.obj"));
  ASSERT_NE(out.attributes.find_corner("uv"), nullptr);
  EXPECT_EQ(out.attributes.find_corner("uv")->corners, spot.attributes.find_corner("uv")->corners);
  EXPECT_EQ(out.F, spot.F);
  const auto stl = run_cli("enhance " + quoted_data_path("spot.obj") + " " + test::quoted(dir.file("out.stl")));
  ASSERT_EQ(stl.exit_code, 0) << stl.err;
  EXPECT_NE(stl.err.find("out.stl: STL cannot hold, so it does not get: corner uv"), std::string::npos) << stl.err;
  const auto remesh = run_cli("remesh " + quoted_data_path("spot.obj") + " " + test::quoted(dir.file("r.obj")) +
                              " --target-vertices 1000");
  ASSERT_EQ(remesh.exit_code, 0) << remesh.err;
  EXPECT_NE(
      remesh.err.find("remesh builds new faces and vertices and does not carry the input's attributes: corner uv"),
      std::string::npos)
      << remesh.err;
}

// The lines of a text.
std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

// The subcommands `vertexflow --help` lists.
std::vector<std::string> subcommands() {
  std::vector<std::string> commands;
  bool in_subcommands = false;
  for (const std::string& line : lines_of(run_cli("--help").out)) {
    if (line == "Subcommands:") in_subcommands = true;
    std::smatch m;
    if (in_subcommands && std::regex_match(line, m, std::regex(R"(  ([a-z][a-z-]*)\b.*)"))) commands.push_back(m[1]);
  }
  return commands;
}

// A closed tetrahedron in DIR/in.obj, an input every command takes.
std::filesystem::path tetrahedron_in(const test::ScratchDir& dir) {
  const auto input = dir.file("in.obj");
  std::ofstream(input) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
  return input;
}

// Every floating-point option of every subcommand, as their --help lists them (CLI11's FLOAT),
// refuses nan, inf and -inf before anything is read: one line naming the option, exit 1, nothing
// written (issue 32 item 3: `render --view custom --azimuth nan` wrote a blank PNG with exit 0,
// and a NaN passed every range check).
TEST(Cli, EveryFloatingPointOptionRefusesNanAndInfinity) {
  test::ScratchDir dir("cli-non-finite");
  const auto input = tetrahedron_in(dir);
  const std::vector<std::string> commands = subcommands();
  ASSERT_GE(commands.size(), 11u);
  // "  --frame FLOAT x 6", "    --edge-length FLOAT:POSITIVE", "  --weights FLOAT ..."
  const std::regex float_option(R"(\s+(?:-\w,)?(--[\w-]+) FLOAT\S*(?: x (\d+))?.*)");
  int checked = 0;
  std::vector<std::string> seen;
  for (const std::string& command : commands) {
    const std::string extension = command == "render" ? ".png" : command == "lines" ? ".svg" : ".obj";
    const auto output = dir.file("out-" + command + (command == "batch" ? "" : extension));
    for (const std::string& line : lines_of(run_cli(command + " --help").out)) {
      std::smatch m;
      if (!std::regex_match(line, m, float_option)) continue;
      const std::string option = m[1];
      seen.push_back(command + " " + option);
      const int count = m[2].matched ? std::stoi(m[2]) : 1;
      for (const std::string bad : {"nan", "inf", "-inf"}) {
        std::string values = bad;
        for (int i = 1; i < count; ++i) values += " 1";
        const std::string arguments =
            command + " " + test::quoted(input) + " " + test::quoted(output) + " " + option + " " + values;
        const auto r = run_cli(arguments);
        ++checked;
        EXPECT_EQ(r.exit_code, 1) << arguments << "\n" << r.err;
        EXPECT_EQ(r.err.rfind("vertexflow: error: ", 0), 0u) << arguments << "\n" << r.err;
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << arguments << "\n" << r.err;
        EXPECT_NE(r.err.find(option + ": " + bad), std::string::npos) << arguments << "\n" << r.err;
        EXPECT_FALSE(std::filesystem::exists(output)) << arguments;
      }
    }
  }
  // The help was read: the camera's angles and the enhance table's options are among them.
  for (const char* expected :
       {"render --azimuth", "render --elevation", "lines --azimuth", "lines --frame", "compare-lines --elevation",
        "remesh --edge-length", "enhance --lambda", "batch --lambda"})
    EXPECT_NE(std::find(seen.begin(), seen.end(), expected), seen.end()) << expected;
  EXPECT_GT(checked, 100);
  // An angle in range still draws (the check is for non-finite values only).
  const auto good = dir.file("good.png");
  const auto r = run_cli("render " + test::quoted(input) + " " + test::quoted(good) +
                         " --view custom --azimuth 400 --elevation -90 --size 64x48");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(std::filesystem::exists(good));
}

// Every numeric option's errors in the same words, from one place (cli_common's
// plain_option_messages and the option table): the option as typed, the range in plain numbers,
// one line, exit 1, and never the input file (issue 32 item 10: `--feature-angle inf` printed a
// bound of 309 digits and exited 105; `--samples 1e20` and `--lambda abc` "could not convert").
TEST(Cli, OptionErrorsNameTheOptionAndStateTheRangePlainly) {
  test::ScratchDir dir("cli-option-errors");
  const auto input = tetrahedron_in(dir);
  const std::vector<std::string> commands = subcommands();
  ASSERT_GE(commands.size(), 11u);
  const std::regex numeric_option(R"(\s+(?:-\w,)?(--[\w-]+) (INT|UINT|FLOAT)(\S*)(?: x (\d+))?.*)");
  const std::regex long_number(R"(\d{13})");
  int checked = 0;
  for (const std::string& command : commands) {
    const std::string extension = command == "render" ? ".png" : command == "lines" ? ".svg" : ".obj";
    const auto output = dir.file("out-" + command + (command == "batch" ? "" : extension));
    for (const std::string& line : lines_of(run_cli(command + " --help").out)) {
      std::smatch m;
      if (!std::regex_match(line, m, numeric_option)) continue;
      const std::string option = m[1], type = m[2];
      const int count = m[4].matched ? std::stoi(m[4]) : 1;
      const auto run = [&](const std::string& bad) {
        std::string values = bad;
        for (int i = 1; i < count; ++i) values += " 1";
        const std::string arguments = command + " " + test::quoted(input) + " " + test::quoted(output) + " " + option +
                                      " " + values + (command == "render" || command == "lines" ? " --size 32x32" : "");
        ++checked;
        return std::make_pair(arguments, run_cli(arguments));
      };
      // Not a number of the option's kind: said so, naming the option.
      const auto [arguments, r] = run("abc");
      const std::string kind = type == "FLOAT" ? "a number" : type == "UINT" ? "an integer >= 0" : "an integer";
      EXPECT_EQ(r.exit_code, 1) << arguments;
      EXPECT_EQ(r.err, "vertexflow: error: " + option + ": 'abc' is not " + kind + "\n") << arguments;
      // Far below any range (every CLI11 range here is above -1e300): the range in plain numbers.
      const auto [low_arguments, low] = run(type == "FLOAT" ? "-1e300" : "-1");
      if (!m[3].str().empty()) {
        EXPECT_EQ(low.exit_code, 1) << low_arguments;  // a CLI11 check: refused
      }
      if (low.exit_code != 0) {
        // "--x: VALUE ...", or "--x does not apply to ..." of the enhance modes.
        EXPECT_EQ(low.err.rfind("vertexflow: error: " + option, 0), 0u) << low_arguments << "\n" << low.err;
        EXPECT_EQ(std::count(low.err.begin(), low.err.end(), '\n'), 1) << low_arguments << "\n" << low.err;
        EXPECT_FALSE(std::regex_search(low.err, long_number)) << low_arguments << "\n" << low.err;
        EXPECT_EQ(low.err.find(input.filename().string()), std::string::npos) << low_arguments << "\n" << low.err;
      }
      std::filesystem::remove_all(output);
    }
  }
  EXPECT_GT(checked, 150);
  // The issue's own and a few more, word for word.
  const struct {
    std::string arguments, error;
  } cases[] = {
      {"enhance IN o.obj --feature-angle inf", "--feature-angle: inf is not in the allowed range (>= 0)"},
      {"enhance IN o.obj --lambda nan", "--lambda: nan is not in the allowed range (> 0)"},
      {"enhance IN o.obj --iterations 1e9", "--iterations: '1e9' is not an integer"},
      {"enhance IN o.obj --iterations 99999999999999999999", "--iterations: 99999999999999999999 is too large"},
      {"enhance IN o.obj --method unsharp --weight inf", "--weight: inf is not a finite number"},
      {"render IN o.png --exaggeration -1", "--exaggeration: -1 is not in the allowed range (> 0)"},
      {"render IN o.png --elevation 100", "--elevation: 100 is not in the allowed range ([-90, 90])"},
      {"render IN o.png --samples 1e20", "--samples: '1e20' is not an integer"},
      {"lines IN o.svg --line-width 100", "--line-width: 100 is not in the allowed range ([0.1, 16])"},
      {"remesh IN o.obj --edge-length 0", "--edge-length: 0 is not in the allowed range (> 0)"},
      {"compare IN IN --seed -1", "--seed: '-1' is not an integer >= 0"},
      {"batch IN out -j 0", "--jobs: 0 is not in the allowed range ([1, 1024])"},
      // Checks of options against each other come before the mesh is read, naming no file.
      {"render IN o.png --shading exaggerated --weights 1,2",
       "--weights: 2 values given for 4 scales; expected 5 (scales + 1)"},
      {"render IN o.png --shading exaggerated --light 0,0,0", "--light: 0,0,0 is not a direction"},
      {"render IN o.png --color displacement", "--color displacement needs --before MESH"},
  };
  for (const auto& c : cases) {
    const std::string arguments = std::regex_replace(c.arguments, std::regex("IN"), test::quoted(input));
    const auto r = run_cli("-q " + arguments);
    EXPECT_EQ(r.exit_code, 1) << arguments;
    EXPECT_EQ(r.err, "vertexflow: error: " + c.error + "\n") << arguments;
  }
}

// --size is checked as it is parsed: the range, not "expected WIDTHxHEIGHT", for a size of the
// right form, and no mesh file named (issue 32 item 11).
TEST(Cli, ImageSizeOutOfRangeStatesTheRange) {
  test::ScratchDir dir("cli-image-size");
  const auto input = dir.file("in.obj"), output = dir.file("out.png");
  std::ofstream(input) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
  for (const std::string command : {"render", "lines", "compare-lines"}) {
    for (const std::string size : {"100000x100000", "40000x40000", "8x8", "16x99999999999999999999"}) {
      const std::string arguments =
          command + " " + test::quoted(input) + " " +
          (command == "compare-lines" ? test::quoted(input)
                                      : test::quoted(command == "lines" ? dir.file("out.svg") : output)) +
          " --size " + size;
      const auto r = run_cli(arguments);
      EXPECT_EQ(r.exit_code, 1) << arguments;
      EXPECT_EQ(r.err, "vertexflow: error: --size " + size + ": width and height must each be in [16, 8192] pixels\n")
          << arguments;
    }
    const auto malformed =
        run_cli(command + " " + test::quoted(input) + " " + test::quoted(dir.file("o.svg")) + " --size 100000by100000");
    EXPECT_EQ(malformed.err, "vertexflow: error: --size 100000by100000: expected WIDTHxHEIGHT, e.g. 1600x1200\n");
  }
  EXPECT_FALSE(std::filesystem::exists(output));
  // Leading zeros are digits like any other.
  const auto r = run_cli("render " + test::quoted(input) + " " + test::quoted(output) + " --size 00064x048");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(std::filesystem::exists(output));
}

TEST(Cli, UsageErrorsFail) {
  EXPECT_NE(run_cli("").exit_code, 0);
  EXPECT_NE(run_cli("info").exit_code, 0);
  EXPECT_NE(run_cli("frobnicate x.off").exit_code, 0);
  // One line and exit 1, as every error (CLI11 adds a hint line and exits 105-109 by kind).
  const auto out_of_range = run_cli("render in.obj out.png --elevation 100");
  EXPECT_EQ(out_of_range.exit_code, 1);
  EXPECT_EQ(out_of_range.err.rfind("vertexflow: error: --elevation", 0), 0u) << out_of_range.err;
  EXPECT_EQ(std::count(out_of_range.err.begin(), out_of_range.err.end(), '\n'), 1) << out_of_range.err;
  const auto version = run_cli("--version");
  EXPECT_EQ(version.exit_code, 0);
  EXPECT_NE(version.out.find("vertexflow"), std::string::npos);
}

// The allocator the CLI was built with (apps/allocator.cpp). With jemalloc, huge pages are on
// only if jemalloc read the options the binary defines: a malloc_conf it did not see (a symbol
// not interposed) leaves opt.thp at "default", and the speed-up is gone.
TEST(Cli, SaysWhichAllocatorItRunsOn) {
  const auto version = run_cli("--version");
  ASSERT_EQ(version.exit_code, 0);
#if defined(VERTEXFLOW_CLI_WITH_JEMALLOC)
  EXPECT_NE(version.out.find("allocator: jemalloc"), std::string::npos) << version.out;
  EXPECT_NE(version.out.find("transparent huge pages: always"), std::string::npos) << version.out;
#else
  EXPECT_NE(version.out.find("allocator: the C library's malloc"), std::string::npos) << version.out;
#endif
}

}  // namespace
}  // namespace vertexflow

namespace vertexflow {
namespace {

TEST(CliCurvature, WritesPropertiesAndColours) {
  test::ScratchDir dir("cli-curvature");
  const auto out = dir.file("torus.ply");
  const auto r = test::run_cli("curvature " + quoted_data_path("torus.obj") + " " + test::shell_quote(out.string()) +
                               " --color mean --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  // torus.obj: R = 1, r = 0.25, so k1 = 1/r = 4 on every vertex.
  EXPECT_NEAR(j["k1"]["median"].get<double>(), 4.0, 0.04);
  EXPECT_LT(j["color"]["min"].get<double>(), 0.0);
  const Mesh mesh = read_mesh(out);
  for (const char* name : {"k1", "k2", "H", "K", "T1x", "T1y", "T1z", "T2x", "T2y", "T2z"})
    EXPECT_NE(mesh.find_vertex_property(name), nullptr) << name;
  const Colors colors = mesh.vertex_colors();
  EXPECT_EQ(colors.rows(), mesh.num_vertices());
  // Positive mean curvature is red, on the outer equator of the torus.
  const Eigen::VectorXd& H = mesh.find_vertex_property("H")->values;
  Index most_positive = 0;
  H.maxCoeff(&most_positive);
  EXPECT_GT(colors(most_positive, 0), colors(most_positive, 2));
}

TEST(CliCurvature, RefusesToOverwriteTheInputAndTakesNonManifoldMeshes) {
  test::ScratchDir dir("cli-curvature-refuse");
  const auto copy = dir.file("in.ply");
  std::filesystem::copy_file(test::data_path("horse-48k.ply"), copy);
  const std::string before = test::read_text(copy);
  const auto r =
      test::run_cli("curvature " + test::shell_quote(copy.string()) + " " + test::shell_quote(copy.string()));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("refusing to overwrite"), std::string::npos) << r.err;
  EXPECT_EQ(test::read_text(copy), before);

  const auto nm = test::run_cli("curvature " + quoted_data_path("suzanne.obj") + " " +
                                test::shell_quote(dir.file("s.ply").string()));
  EXPECT_EQ(nm.exit_code, 0) << nm.err;  // suzanne triangulates to a manifold mesh
  const auto bad = dir.file("bowtie.obj");
  { std::ofstream(bad) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv -1 0 0\nv 0 -1 0\nf 1 2 3\nf 1 4 5\n"; }
  // A non-manifold mesh is estimated on its manifold split (curvature.h): a flat bowtie has
  // zero curvature everywhere.
  const auto bowtie = test::run_cli("curvature " + test::shell_quote(bad.string()) + " " +
                                    test::shell_quote(dir.file("b.ply").string()));
  EXPECT_EQ(bowtie.exit_code, 0) << bowtie.err;
  EXPECT_EQ(read_mesh(dir.file("b.ply")).num_vertices(), 5);
}

}  // namespace
}  // namespace vertexflow

namespace vertexflow {
namespace {

TEST(CliEnhance, WritesTheMeshAndAReport) {
  test::ScratchDir dir("cli-enhance");
  const auto out = dir.file("bunny.ply");
  const auto report = dir.file("report.json");
  const auto pins = dir.file("pins.txt");
  { std::ofstream(pins) << "# hold two vertices\n17 4000\n"; }
  const auto r = run_cli("enhance " + quoted_data_path("bunny_uniform.off") + " " + shell_quote(out.string()) +
                         " --pin " + shell_quote(pins.string()) + " --report " + shell_quote(report.string()));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Mesh input = read_mesh(test::data_path("bunny_uniform.off"));
  const Mesh result = read_mesh(out);
  ASSERT_EQ(result.F, input.F);
  EXPECT_EQ(result.V.row(17), input.V.row(17));
  EXPECT_EQ(result.V.row(4000), input.V.row(4000));
  EXPECT_GT((result.V - input.V).rowwise().norm().maxCoeff(), 0.0);
  const auto j = nlohmann::json::parse(test::read_text(report));
  EXPECT_EQ(j["flipped_faces"], 0);
  EXPECT_EQ(j["degenerate_faces"], 0);
  EXPECT_EQ(j["options"]["pinned"], 2);
  // The flow redistributes vertices towards curved regions and evens out the edge errors.
  EXPECT_GT(j["redistribution_rho"]["result"].get<double>(), j["redistribution_rho"]["input"].get<double>() + 0.2);
  EXPECT_LT(j["edge_error_cv"]["result"].get<double>(), 0.95 * j["edge_error_cv"]["input"].get<double>());
  EXPECT_LT(j["drift_edge_lengths"]["mean"].get<double>(), 0.05);
  EXPECT_GE(j["drift_edge_lengths"]["hausdorff"].get<double>(), j["drift_edge_lengths"]["max"].get<double>());
  for (const char* phase : {"read", "curvature", "assembly", "solve", "guard", "write"})
    EXPECT_GE(j["seconds"][phase].get<double>(), 0.0) << phase;
}

TEST(CliEnhance, BadPinFileFailsCleanly) {
  test::ScratchDir dir("cli-enhance-bad");
  const auto pins = dir.file("pins.txt");
  { std::ofstream(pins) << "12 banana\n"; }
  const auto out = dir.file("out.off");
  const auto r = run_cli("enhance " + quoted_data_path("spot.obj") + " " + shell_quote(out.string()) + " --pin " +
                         shell_quote(pins.string()));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("line 1: 'banana' is not a vertex index"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(out));
}

// A non-manifold mesh (a bowtie: two triangles sharing only vertex 1) is flowed with its
// non-manifold vertex held, and says so in one warning line; --strict refuses it in one line.
TEST(CliEnhance, NonManifoldInputIsHeldWhereItMustBeOrRefusedWithStrict) {
  test::ScratchDir dir("cli-enhance-non-manifold");
  const auto bowtie = dir.file("bowtie.obj"), out = dir.file("out.obj"), report = dir.file("r.json");
  { std::ofstream(bowtie) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv -1 0 0\nv 0 -1 0\nf 1 2 3\nf 1 4 5\n"; }
  const auto held = run_cli("enhance " + shell_quote(bowtie.string()) + " " + shell_quote(out.string()) + " --report " +
                            shell_quote(report.string()));
  EXPECT_EQ(held.exit_code, 0) << held.err;
  EXPECT_NE(held.err.find("bowtie.obj: the mesh is not manifold or not consistently oriented: 1 vertices held"),
            std::string::npos)
      << held.err;
  const auto json = nlohmann::json::parse(test::read_text(report));
  EXPECT_EQ(json["non_manifold"]["held_vertices"], 1);
  EXPECT_EQ(json["vertices"], 5);
  EXPECT_EQ(read_mesh(out).V, read_mesh(bowtie).V);  // every vertex on the boundary or held
  std::filesystem::remove(out);
  const auto strict =
      run_cli("--quiet enhance " + shell_quote(bowtie.string()) + " " + shell_quote(out.string()) + " --strict");
  EXPECT_EQ(strict.exit_code, 1);
  EXPECT_NE(strict.err.find("bowtie.obj: vertex flow: the mesh is not manifold"), std::string::npos) << strict.err;
  EXPECT_EQ(std::count(strict.err.begin(), strict.err.end(), '\n'), 1) << strict.err;
  EXPECT_FALSE(std::filesystem::exists(out));

  // The same with the flow on a reference: held without --strict; with it, the one line names
  // the input alone, not the reference read after it (it used to read "REFERENCE: INPUT: ...").
  // The reference is the bowtie's plane: one that is not its surface is refused (enhance.h).
  const auto plane = dir.file("plane.obj");
  { std::ofstream(plane) << "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nf 1 2 3\nf 1 3 4\n"; }
  const std::string on_reference = " --reference " + shell_quote(plane.string()) + " --reference-method flow";
  const auto held_on_reference =
      run_cli("enhance " + shell_quote(bowtie.string()) + " " + shell_quote(out.string()) + on_reference);
  EXPECT_EQ(held_on_reference.exit_code, 0) << held_on_reference.err;
  EXPECT_NE(held_on_reference.err.find("1 vertices held"), std::string::npos) << held_on_reference.err;
  std::filesystem::remove(out);
  const auto strict_on_reference = run_cli("--quiet enhance " + shell_quote(bowtie.string()) + " " +
                                           shell_quote(out.string()) + on_reference + " --strict");
  EXPECT_EQ(strict_on_reference.exit_code, 1);
  EXPECT_EQ(strict_on_reference.err.rfind(
                "vertexflow: error: " + bowtie.string() + ": vertex flow: the mesh is not manifold", 0),
            0)
      << strict_on_reference.err;
  EXPECT_EQ(strict_on_reference.err.find("plane.obj"), std::string::npos) << strict_on_reference.err;
  EXPECT_FALSE(std::filesystem::exists(out));
}

}  // namespace
}  // namespace vertexflow

namespace vertexflow {
namespace {

// Values CLI11's checks let through (NaN passes "> 0" and range checks, as every comparison with
// it is false) are refused by the library (validate_flow_options, unsharp_mask): one line naming
// the input, nothing written.
// Non-finite and out-of-range values are refused as they are parsed, by the option table's
// ranges (enhance_options.h), naming the flag: one line, exit 1, nothing written.
TEST(CliEnhance, NonFiniteOptionsAreOneLineNamingTheFlag) {
  test::ScratchDir dir("cli-enhance-refused");
  const auto out = dir.file("out.ply"), report = dir.file("r.json");
  const std::string input = test::data_path("spot.obj").string();
  const struct {
    std::string options;
    std::string problem;
  } cases[] = {{"--lambda nan", "--lambda: nan is not in the allowed range (> 0)"},
               {"--mu nan", "--mu: nan is not in the allowed range (>= 0)"},
               {"--min-quality nan", "--min-quality: nan is not in the allowed range ([0, 1])"},
               {"--feature-angle nan", "--feature-angle: nan is not in the allowed range (>= 0)"},
               {"--lambda -2", "--lambda: -2 is not in the allowed range (> 0)"},
               {"--method unsharp --weight inf", "--weight: inf is not a finite number"}};
  for (const auto& c : cases) {
    const auto r = run_cli("--quiet enhance " + shell_quote(input) + " " + shell_quote(out.string()) + " " + c.options +
                           " --report " + shell_quote(report.string()));
    EXPECT_EQ(r.exit_code, 1) << c.options;
    EXPECT_EQ(r.err, "vertexflow: error: " + c.problem + "\n") << c.options;
    EXPECT_FALSE(std::filesystem::exists(out)) << c.options;
    EXPECT_FALSE(std::filesystem::exists(report)) << c.options;
  }
}

TEST(CliEnhance, PinFileMustBeARegularFileOfBoundedSize) {
  test::ScratchDir dir("cli-enhance-pins");
  const auto out = dir.file("out.ply");
  const auto fifo = dir.file("pins.fifo");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  // spot.obj has 2930 vertices: its pin list may be 1 MiB + 16 bytes per vertex. Two MB of
  // valid indices is still too much.
  const auto large = dir.file("large.txt");
  {
    std::ofstream file(large);
    for (int i = 0; i < 1'000'000; ++i) file << "0\n";
  }
  const struct {
    std::filesystem::path pins;
    std::string problem;
  } cases[] = {{fifo, "is a FIFO, not a pin file"},
               {"/dev/zero", "is a device, not a pin file"},
               {dir.path(), "is a directory, not a pin file"},
               {large, "is larger than a pin list for 2930 vertices can be"},
               {dir.file("missing.txt"), "cannot open the pin file: No such file or directory"}};
  for (const auto& c : cases) {
    // `timeout`: a pin file that blocks (a FIFO without a writer) fails the test instead of
    // hanging it.
    const auto r =
        test::run_command("timeout 60 " + shell_quote(VERTEXFLOW_CLI) + " enhance " + quoted_data_path("spot.obj") +
                          " " + shell_quote(out.string()) + " --pin " + shell_quote(c.pins.string()));
    EXPECT_EQ(r.exit_code, 1) << c.pins;
    if (c.pins == large) {  // the bound depends on the mesh, so this is found after reading it
      const std::string line = "vertexflow: error: " + c.pins.string() + ": " + c.problem + " (" +
                               std::to_string((1 << 20) + 16 * 2930) + " bytes)\n";
      EXPECT_TRUE(r.err.size() >= line.size() && r.err.compare(r.err.size() - line.size(), line.size(), line) == 0)
          << r.err;
    } else {  // found before the mesh is read: no progress line before the error
      EXPECT_EQ(r.err, "vertexflow: error: " + c.pins.string() + ": " + c.problem + "\n");
    }
    EXPECT_FALSE(std::filesystem::exists(out));
  }
  // A file just under the bound is read.
  {
    std::ofstream file(large);
    file << "# the first vertex, many times\n";
    for (int i = 0; i < ((1 << 20) + 16 * 2930 - 40) / 2; ++i) file << "0\n";
  }
  ASSERT_LE(std::filesystem::file_size(large), static_cast<std::uintmax_t>((1 << 20) + 16 * 2930));
  const auto ok =
      run_cli("--quiet enhance " + quoted_data_path("spot.obj") + " " + shell_quote(out.string()) + " --pin " +
              shell_quote(large.string()) + " --report " + shell_quote(dir.file("r.json").string()));
  EXPECT_EQ(ok.exit_code, 0) << ok.err;
  EXPECT_EQ(nlohmann::json::parse(test::read_text(dir.file("r.json")))["options"]["pinned"],
            ((1 << 20) + 16 * 2930 - 40) / 2);
}

// flow.h: the direct solve runs with one BLAS thread whatever BLAS the process has, so that its
// bytes do not depend on the thread count. The runs load Debian's threaded OpenBLAS
// (libopenblas0-pthread, installed by scripts/setup.sh) in place of the serial build the CLI
// links, with 2 and 4 threads asked for, and must write the serial build's bytes. suzanne
// (507 vertices) takes the direct path by itself; bunny_uniform (8,904) is forced onto it, and
// its supernodes are large enough for OpenBLAS to thread: with the thread count forced to 2
// inside vertex_flow its bytes differ from the serial build's (checked by hand, issue 14).
TEST(CliEnhance, SameBytesWhateverTheBlasThreadCount) {
  const std::string threaded = "/usr/lib/x86_64-linux-gnu/openblas-pthread/libblas.so.3";
  ASSERT_TRUE(std::filesystem::exists(threaded)) << threaded << " is missing: scripts/setup.sh installs it";
  test::ScratchDir dir("cli-enhance-blas-threads");
  for (const std::string mesh : {"suzanne.obj", "bunny_uniform.off"}) {
    SCOPED_TRACE(mesh);
    // suzanne looks like a control mesh: held unless --assume-on-surface (input_check.h).
    const std::string arguments = " --quiet enhance " + quoted_data_path(mesh) + " " +
                                  shell_quote(dir.file("out.ply").string()) + " --report " +
                                  shell_quote(dir.file("report.json").string()) +
                                  (mesh == "suzanne.obj" ? " --assume-on-surface" : " --solver direct");
    std::string serial;
    for (const std::string& environment : {std::string(), "LD_PRELOAD=" + threaded + " OPENBLAS_NUM_THREADS=2",
                                           "LD_PRELOAD=" + threaded + " OPENBLAS_NUM_THREADS=4"}) {
      SCOPED_TRACE(environment);
#ifdef VERTEXFLOW_TEST_ASAN
      // An instrumented CLI refuses to start when a preloaded library comes before ASan's runtime.
      const std::string sanitizer = " ASAN_OPTIONS=verify_asan_link_order=0";
#else
      const std::string sanitizer;
#endif
      const auto r =
          test::run_command(environment + sanitizer + " LD_DEBUG=libs " + shell_quote(VERTEXFLOW_CLI) + arguments);
      ASSERT_EQ(r.exit_code, 0) << r.err;
      // The BLAS that was loaded (the dynamic linker's log), and the solver that ran.
      const bool loaded_threaded =
          r.err.find("calling init: /usr/lib/x86_64-linux-gnu/openblas-pthread/") != std::string::npos;
      EXPECT_EQ(loaded_threaded, !environment.empty());
      EXPECT_EQ(nlohmann::json::parse(test::read_text(dir.file("report.json")))["solver"]["method"],
                "direct (CHOLMOD)");
      const std::string bytes = test::read_text(dir.file("out.ply"));
      ASSERT_FALSE(bytes.empty());
      if (environment.empty()) {
        serial = bytes;
        // The flow ran: the output is not the input.
        EXPECT_NE(read_mesh(dir.file("out.ply")).V, read_mesh(test::data_path(mesh)).V);
      } else {
        EXPECT_TRUE(bytes == serial) << "different bytes with the threaded BLAS";
      }
    }
  }
}

TEST(CliEnhance, RefusesAReportOverTheOutput) {
  test::ScratchDir dir("cli-enhance-report");
  const auto out = dir.file("out.ply");
  const auto r = run_cli("enhance " + quoted_data_path("spot.obj") + " " + shell_quote(out.string()) + " --report " +
                         shell_quote(out.string()));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("would overwrite another output of the same command"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(out));
}

}  // namespace
}  // namespace vertexflow

namespace vertexflow {
namespace {

// Issue 32: a flat grid in z = 0 and a bumpy one (24 x 24 vertices over the unit square, two
// triangles per cell), written as OBJ.
void write_grid(const std::filesystem::path& path, double bump, double scale = 1, double shift = 0) {
  constexpr int n = 24;
  std::ofstream out(path);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const double x = i / (n - 1.0), y = j / (n - 1.0);
      out << "v " << scale * x + shift << ' ' << scale * y << ' '
          << scale * bump * std::sin(3 * M_PI * x) * std::sin(3 * M_PI * y) << '\n';
    }
  for (int j = 0; j + 1 < n; ++j)
    for (int i = 0; i + 1 < n; ++i) {
      const int a = j * n + i + 1;
      out << "f " << a << ' ' << a + 1 << ' ' << a + n + 1 << "\nf " << a << ' ' << a + n + 1 << ' ' << a + n << '\n';
    }
}

// Item 1: the flat grid comes back as it went in (before: its 484 inner vertices moved by up to
// 2.34 mean edge lengths) and the run says why.
TEST(CliEnhance, AFlatMeshComesBackUnchanged) {
  test::ScratchDir dir("cli-enhance-flat");
  write_grid(dir.file("flat.obj"), 0);
  const auto r = run_cli("enhance " + test::quoted(dir.file("flat.obj")) + " " + test::quoted(dir.file("out.obj")));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("nothing to enhance"), std::string::npos) << r.err;
  EXPECT_EQ(read_mesh(dir.file("out.obj")).V, read_mesh(dir.file("flat.obj")).V);
}

// Item 2: a reference shifted by 1e6, scaled by 1e-9 or reduced to one triangle is refused with
// one line naming both files, with either reference method; the help says what a reference must be.
TEST(CliEnhance, AReferenceThatDoesNotOverlapIsRefusedNamingBothFiles) {
  test::ScratchDir dir("cli-enhance-reference");
  const auto input = dir.file("bumpy.obj");
  write_grid(input, 0.08);
  write_grid(dir.file("shifted.obj"), 0.08, 1, 1e6);
  write_grid(dir.file("tiny.obj"), 0.08, 1e-9);
  { std::ofstream(dir.file("triangle.obj")) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"; }
  for (const char* reference : {"shifted.obj", "tiny.obj", "triangle.obj"})
    for (const char* method : {"fit", "flow"}) {
      SCOPED_TRACE(std::string(reference) + ", " + method);
      const auto r = run_cli("--quiet enhance " + test::quoted(input) + " " + test::quoted(dir.file("out.obj")) +
                             " --reference " + test::quoted(dir.file(reference)) + " --reference-method " + method);
      EXPECT_EQ(r.exit_code, 1);
      EXPECT_EQ(
          r.err.rfind("vertexflow: error: " + input.string() + ": the reference " + dir.file(reference).string() + " ",
                      0),
          0u)
          << r.err;
      EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
      EXPECT_FALSE(std::filesystem::exists(dir.file("out.obj")));
    }
  const auto same = run_cli("--quiet enhance " + test::quoted(input) + " " + test::quoted(dir.file("out.obj")) +
                            " --reference " + test::quoted(input));
  EXPECT_EQ(same.exit_code, 0) << same.err;
  const auto help = run_cli("enhance --help");
  EXPECT_NE(help.out.find("within 10x the input's"), std::string::npos) << help.out;
}

// Item 9: an exponent where the density is 0 or inf everywhere (before: accepted, exit 0) is
// refused by its flag, with its range.
TEST(CliEnhance, ADensityExponentBeyondTheBoundIsRefused) {
  test::ScratchDir dir("cli-enhance-exponent");
  const auto r = run_cli("--quiet enhance " + quoted_data_path("bunny_uniform.off") + " " +
                         test::quoted(dir.file("out.ply")) + " --density-passes 3 --density-exponent 1e5");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("--density-exponent: 100000 is not in the allowed range ([0, 10])"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace vertexflow
