// fit_to_reference (fit.h), reference mode of issue 16: a 10k-vertex remesh of bunny.off fitted
// to bunny.off subdivided 1-to-16 (557k vertices, 1.1M faces), the tree over the reference and
// the sampling included; and the same remesh against bunny.off itself (35k vertices). Counters:
// rounds and the phases of FitReport in milliseconds per run. Also smooth mode and the paper's
// flow on the same remesh. Results: docs/benchmarks.md.
//
//   build/bin/bench_fit --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include "bench_support.h"

#include "vertexflow/fit.h"
#include "vertexflow/flow.h"
#include "vertexflow/io.h"
#include "vertexflow/remesh.h"

#include <benchmark/benchmark.h>

#include <iostream>

namespace vertexflow::bench {
namespace {

const Mesh& dense_bunny() {
  static const Mesh mesh = read_mesh(data_dir() / "bunny.off");
  return mesh;
}

const Mesh& coarse_bunny() {
  static const Mesh mesh = [] {
    RemeshOptions options;
    options.target_vertices = 10000;
    return remesh_to_vertex_count(dense_bunny().V, dense_bunny().F, options).mesh;
  }();
  return mesh;
}

const Mesh& subdivided_bunny() {
  static const Mesh mesh = subdivide_uniform(dense_bunny(), 4);
  return mesh;
}

// Runs fit(coarse) and reports the last run's rounds and phases (FitReport) as counters.
template <class Fit>
void run_fit(benchmark::State& state, Fit&& fit) {
  const Mesh& coarse = coarse_bunny();
  FitReport report;
  for (auto _ : state) {
    FitResult result = fit(coarse);
    benchmark::DoNotOptimize(result.V.data());
    report = result.report;
  }
  state.counters["vertices"] = static_cast<double>(coarse.num_vertices());
  state.counters["rounds"] = report.rounds;
  state.counters["surface_ms"] = 1e3 * report.seconds_surface;
  state.counters["tree_ms"] = 1e3 * report.seconds_tree;
  state.counters["queries_ms"] = 1e3 * report.seconds_queries;
  state.counters["solve_ms"] = 1e3 * report.seconds_solve;
  state.counters["guard_ms"] = 1e3 * report.seconds_guard;
}

void run(benchmark::State& state, const Mesh& reference) {
  run_fit(state, [&](const Mesh& coarse) { return fit_to_reference(coarse.V, coarse.F, reference.V, reference.F); });
  state.counters["reference_vertices"] = static_cast<double>(reference.num_vertices());
}

void BM_FitTo557k(benchmark::State& state) {
  run(state, subdivided_bunny());
}
void BM_FitTo35k(benchmark::State& state) {
  run(state, dense_bunny());
}

// Smooth mode and the paper's flow on the same 10k remesh (issue 16: smooth mode at most 3x the
// paper's mode).
void BM_SmoothMode(benchmark::State& state) {
  run_fit(state, [](const Mesh& coarse) { return fit_to_smooth_surface(coarse.V, coarse.F); });
}
void BM_PaperMode(benchmark::State& state) {
  const Mesh& coarse = coarse_bunny();
  for (auto _ : state) {
    FlowResult result = vertex_flow(coarse.V, coarse.F);
    benchmark::DoNotOptimize(result.V.data());
  }
}

BENCHMARK(BM_FitTo557k)->Name("fit/bunny-10k/reference-557k")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_FitTo35k)->Name("fit/bunny-10k/reference-35k")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_SmoothMode)->Name("fit/bunny-10k/smooth")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_PaperMode)->Name("fit/bunny-10k/paper-flow")->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace vertexflow::bench

BENCHMARK_MAIN();
