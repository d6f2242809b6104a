// `vertexflow compare` end to end: the table, the JSON keys, not-applicable flips, one-line errors.
#include "test_support.h"

#include "vertexflow/compare.h"
#include "vertexflow/io.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fstream>

namespace vertexflow {
namespace {

using test::quoted_data_path;
using test::run_cli;
using test::shell_quote;

TEST(CliCompare, JsonHasEveryMetricAndMatchesTheLibrary) {
  test::ScratchDir dir("cli-compare-json");
  // A result with the input's connectivity: the input with one vertex moved a little.
  Mesh input = read_mesh(test::data_path("bunny_uniform.off"));
  Mesh result = input;
  result.V.row(100) += 0.2 * (result.V.row(101) - result.V.row(100));
  const auto result_file = dir.file("result.ply");
  write_mesh(result_file, result);
  const auto r = run_cli("compare " + shell_quote(result_file.string()) + " " + quoted_data_path("bunny_uniform.off") +
                         " --reference " + quoted_data_path("bunny.off") + " --json --samples 20000 --seed 5");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  for (const char* key :
       {"result", "input", "reference", "samples", "seed", "length_scale", "distance", "curvature_surface",
        "edge_error", "redistribution_rho", "abs_mean_curvature", "quality", "degenerate_faces", "flipped_faces"})
    EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_EQ(j["samples"], 20000);
  EXPECT_EQ(j["seed"], 5);
  EXPECT_EQ(j["length_scale"]["of"], "reference");
  EXPECT_EQ(j["curvature_surface"], "reference");
  EXPECT_EQ(j["reference"]["vertices"], 34835);
  for (const char* pair : {"result_input", "result_reference", "input_reference"}) {
    const auto& d = j["distance"][pair];
    EXPECT_GE(d["hausdorff"].get<double>(), 0.0) << pair;
    EXPECT_NEAR(d["hausdorff_relative"].get<double>(),
                d["hausdorff"].get<double>() / j["length_scale"]["diagonal"].get<double>(), 1e-15);
  }
  const auto& to_input = j["distance"]["result_input"]["result_to_input"];
  for (const char* key : {"mean", "rms", "max", "mean_relative", "rms_relative", "max_relative", "points"})
    EXPECT_TRUE(to_input.contains(key)) << key;
  for (const char* side : {"input", "result"}) {
    EXPECT_TRUE(j["edge_error"][side].contains("coefficient_of_variation"));
    EXPECT_TRUE(j["abs_mean_curvature"][side].contains("p99"));
    EXPECT_EQ(j["quality"][side]["histogram"].size(), 10u);
  }
  EXPECT_EQ(j["flipped_faces"]["applicable"], true);
  EXPECT_EQ(j["flipped_faces"]["count"], 0);

  // The same numbers as the library with the same options.
  const Mesh reference = read_mesh(test::data_path("bunny.off"));
  CompareOptions options;
  options.sampling.samples = 20000;
  options.sampling.seed = 5;
  const MeshComparison c = compare_meshes(read_mesh(result_file), input, &reference, options);
  EXPECT_EQ(to_input["mean"].get<double>(), c.result_input.a_to_b.mean);
  EXPECT_EQ(j["distance"]["result_reference"]["reference_to_result"]["max"].get<double>(),
            c.result_reference->b_to_a.max);
  EXPECT_EQ(j["redistribution_rho"]["result"].get<double>(), c.redistribution_rho_result);
  EXPECT_GT(c.result_input.a_to_b.max, 0.0);  // the moved vertex is seen
}

TEST(CliCompare, TableAndNotApplicableFlips) {
  // Different connectivity (two remeshes of the bunny): flips cannot be defined.
  const auto r = run_cli("compare " + quoted_data_path("bunny_adaptive.off") + " " +
                         quoted_data_path("bunny_uniform.off") + " --samples 10000");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* text :
       {"result -> input", "input -> result", "Hausdorff result, input", "redistribution rho", "edge error CV",
        "|H| p95", "quality 2r/R min", "quality histogram", "flipped faces (input -> result)", "not applicable"})
    EXPECT_NE(r.out.find(text), std::string::npos) << text << "\n" << r.out;
  EXPECT_EQ(r.out.find("reference"), std::string::npos) << r.out;  // no reference given

  const auto js = run_cli("compare " + quoted_data_path("bunny_adaptive.off") + " " +
                          quoted_data_path("bunny_uniform.off") + " --samples 10000 --json");
  ASSERT_EQ(js.exit_code, 0) << js.err;
  const auto j = nlohmann::json::parse(js.out);
  EXPECT_EQ(j["flipped_faces"]["applicable"], false);
  EXPECT_FALSE(j["flipped_faces"].contains("count"));
  EXPECT_TRUE(j["reference"].is_null());
  EXPECT_TRUE(j["distance"]["result_reference"].is_null());
  EXPECT_TRUE(j["distance"]["input_reference"].is_null());
  EXPECT_EQ(j["length_scale"]["of"], "input");
}

TEST(CliCompare, BadInputsAreOneLineErrors) {
  test::ScratchDir dir("cli-compare-bad");
  const auto missing = run_cli("compare /nonexistent/result.off " + quoted_data_path("sphere_low.off"));
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_EQ(missing.err.rfind("vertexflow: error: /nonexistent/result.off: ", 0), 0u) << missing.err;
  EXPECT_EQ(std::count(missing.err.begin(), missing.err.end(), '\n'), 1) << missing.err;
  EXPECT_TRUE(missing.out.empty());

  const auto empty = test::test_data_path("bad/empty.off");
  const auto bad = run_cli("compare " + quoted_data_path("sphere_low.off") + " " + shell_quote(empty.string()));
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_NE(bad.err.find(empty.string()), std::string::npos) << bad.err;
  EXPECT_EQ(std::count(bad.err.begin(), bad.err.end(), '\n'), 1) << bad.err;

  const auto bowtie = dir.file("bowtie.obj");
  { std::ofstream(bowtie) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv -1 0 0\nv 0 -1 0\nf 1 2 3\nf 1 4 5\n"; }
  const auto nm = run_cli("--quiet compare " + quoted_data_path("sphere_low.off") + " " +
                          quoted_data_path("sphere_low.off") + " --reference " + shell_quote(bowtie.string()));
  // A non-manifold reference is measured as it is (issue 15).
  EXPECT_EQ(nm.exit_code, 0) << nm.err;

  EXPECT_NE(run_cli("compare " + quoted_data_path("sphere_low.off")).exit_code, 0);  // INPUT missing
  EXPECT_NE(run_cli("compare " + quoted_data_path("sphere_low.off") + " " + quoted_data_path("sphere_low.off") +
                    " --samples -5")
                .exit_code,
            0);
}

}  // namespace
}  // namespace vertexflow
