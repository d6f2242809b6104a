// What carrying attributes costs `enhance` (issue 28's budget: at most 15% more than without them
// on a 10k-vertex textured mesh). Each mesh runs twice through the engine (enhance.h): with its
// texture coordinates (seams as creases, re-sampling) and with them stripped.
//
//   build/bin/bench_attributes --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
//
// "transport_ms" is the re-sampling alone (the report's attributes.seconds), "flow_ms" the flow's
// timed phases (the report's seconds): the rest is the engine's own work (face list, seams).
#include "bench_support.h"

#include "vertexflow/enhance.h"
#include "vertexflow/io.h"

#include <benchmark/benchmark.h>

#include <cmath>
#include <numbers>
#include <string>

namespace vertexflow::bench {
namespace {

// A torus with an elliptic tube (so the flow has curvature to move towards), nu x nv quads split
// in two, texture coordinates (i / nu, j / nv) per corner: the two closing lines are seams.
Mesh textured_torus(int nu, int nv) {
  Mesh m;
  m.V.resize(nu * nv, 3);
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      const double phi = 2 * std::numbers::pi * i / nu, theta = 2 * std::numbers::pi * j / nv;
      const double rho = 1 + 0.45 * std::cos(theta);
      m.V.row(j * nu + i) << rho * std::cos(phi), rho * std::sin(phi), 0.2 * std::sin(theta);
    }
  CornerChannel uv;
  uv.channel.name = "uv";
  uv.channel.components = {"u", "v"};
  uv.channel.role = AttributeRole::TexCoord;
  uv.channel.values.resize((nu + 1) * (nv + 1), 2);
  for (int j = 0; j <= nv; ++j)
    for (int i = 0; i <= nu; ++i) uv.channel.values.row(j * (nu + 1) + i) << double(i) / nu, double(j) / nv;
  m.F.resize(2 * nu * nv, 3);
  uv.corners.resize(2 * nu * nv, 3);
  auto vertex = [&](int i, int j) { return Index((j % nv) * nu + i % nu); };
  auto row = [&](int i, int j) { return std::int32_t(j * (nu + 1) + i); };
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      const int f = 2 * (j * nu + i);
      m.F.row(f) << vertex(i, j), vertex(i + 1, j), vertex(i + 1, j + 1);
      uv.corners.row(f) << row(i, j), row(i + 1, j), row(i + 1, j + 1);
      m.F.row(f + 1) << vertex(i, j), vertex(i + 1, j + 1), vertex(i, j + 1);
      uv.corners.row(f + 1) << row(i, j), row(i + 1, j + 1), row(i, j + 1);
    }
  m.attributes.corner.push_back(std::move(uv));
  return m;
}

void run(benchmark::State& state, const Mesh& input) {
  double transport = 0, flow = 0;
  int runs = 0;
  for (auto _ : state) {
    const EnhanceResult result = enhance(input, nullptr, EnhanceOptions{});
    benchmark::DoNotOptimize(result.mesh.V.data());
    if (result.report.contains("attributes")) transport += result.report["attributes"]["seconds"].get<double>();
    for (const char* phase : {"curvature", "assembly", "factorization", "solve", "projection", "guard"})
      flow += result.report["seconds"][phase].get<double>();
    ++runs;
  }
  state.counters["vertices"] = input.num_vertices();
  state.counters["transport_ms"] = 1000 * transport / std::max(runs, 1);
  state.counters["flow_ms"] = 1000 * flow / std::max(runs, 1);  // the flow's phases, as its report times them
}

void register_cases() {
  static const Mesh torus = textured_torus(140, 72);  // 10,080 vertices
  static const Mesh spot = read_mesh(data_dir() / "spot.obj");
  for (const auto& [name, mesh] : {std::pair<std::string, const Mesh*>{"torus-10k", &torus}, {"spot", &spot}}) {
    static std::vector<Mesh> stripped;
    stripped.reserve(2);
    Mesh& plain = stripped.emplace_back(*mesh);
    plain.attributes = {};
    benchmark::RegisterBenchmark(("enhance/" + name + "/attributes").c_str(),
                                 [m = mesh](benchmark::State& s) { run(s, *m); })
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
    benchmark::RegisterBenchmark(("enhance/" + name + "/none").c_str(),
                                 [m = &plain](benchmark::State& s) { run(s, *m); })
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
  }
}

}  // namespace
}  // namespace vertexflow::bench

int main(int argc, char** argv) {
  vertexflow::bench::register_cases();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
