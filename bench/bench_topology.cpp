// build_topology on the ~1M-vertex test mesh (bench_support.h), with TBB allowed all cores
// and limited to one thread, on the 43k-vertex armadillo it is made from, and on bunny_uniform
// (8.9k vertices; bench_flow's smallest bar).
//
//   build/bin/bench_topology --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include "bench_support.h"

#include "vertexflow/io.h"
#include "vertexflow/topology.h"

#include <benchmark/benchmark.h>
#include <tbb/global_control.h>
#include <tbb/info.h>

#include <iostream>

namespace vertexflow::bench {
namespace {

const Mesh& large_mesh() {
  static const Mesh mesh = [] {
    Mesh m = make_large_test_mesh();
    report_topology(m, std::cerr);  // once, outside any timing loop
    return m;
  }();
  return mesh;
}

const Mesh& bunny() {
  static const Mesh mesh = read_mesh(data_dir() / "bunny_uniform.off");
  return mesh;
}

const Mesh& armadillo() {
  static const Mesh mesh = read_mesh(data_dir() / "armadillo-43k.obj");
  return mesh;
}

void run(benchmark::State& state, const Mesh& mesh) {
  // Argument: TBB threads (0 = TBB's default, all cores).
  const auto threads = static_cast<std::size_t>(state.range(0));
  const auto max_threads = threads > 0 ? threads : static_cast<std::size_t>(tbb::info::default_concurrency());
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, max_threads);
  for (auto _ : state) {
    Topology t = build_topology(mesh.F, mesh.num_vertices());
    benchmark::DoNotOptimize(t.edges.data());
    benchmark::DoNotOptimize(t.ring_vertices.data());
    benchmark::ClobberMemory();
  }
  state.counters["vertices"] = mesh.num_vertices();
  state.counters["faces"] = mesh.num_faces();
  state.counters["tbb_threads"] = static_cast<double>(max_threads);
  state.SetItemsProcessed(state.iterations() * mesh.num_faces());  // faces per second
}

void BM_BuildTopology_1M(benchmark::State& state) {
  run(state, large_mesh());
}
void BM_BuildTopology_Armadillo43k(benchmark::State& state) {
  run(state, armadillo());
}
void BM_BuildTopology_BunnyUniform(benchmark::State& state) {
  run(state, bunny());
}

BENCHMARK(BM_BuildTopology_1M)->ArgName("tbb_threads")->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_BuildTopology_Armadillo43k)
    ->ArgName("tbb_threads")
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_BuildTopology_BunnyUniform)
    ->ArgName("tbb_threads")
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace vertexflow::bench

BENCHMARK_MAIN();
