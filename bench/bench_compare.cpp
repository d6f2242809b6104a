// Mesh distances and compare_meshes on two ~100k-vertex meshes with 200,000 samples per mesh.
//
// The meshes: data/camelhead.off (11,381 vertices) subdivided 1-to-9 (bench_support.h):
// 102,245 vertices and 204,336 faces ("input"), and a copy with every vertex moved by a fixed
// pseudo-random offset of up to 0.2 mean edge lengths in each coordinate ("result": the same
// connectivity, like a result of the flow). Each distance direction measures 200,000 area samples
// plus 102k vertices plus 307k edge midpoints: about 610k closest-point queries.
//
//   build/bin/bench_compare --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include "bench_support.h"

#include "vertexflow/compare.h"
#include "vertexflow/distance.h"
#include "vertexflow/io.h"

#include <benchmark/benchmark.h>
#include <tbb/global_control.h>
#include <tbb/info.h>

#include <iostream>
#include <random>

namespace vertexflow::bench {
namespace {

struct Pair {
  Mesh input;
  Mesh result;
};

const Pair& meshes() {
  static const Pair pair = [] {
    Pair p;
    p.input = subdivide_uniform(read_mesh(data_dir() / "camelhead.off"), 3);
    report_topology(p.input, std::cerr);
    const double edge = mean_edge_length(p.input.V, build_topology(p.input.F, p.input.num_vertices()));
    p.result = p.input;
    std::mt19937_64 random(7);
    std::uniform_real_distribution<double> offset(-0.2 * edge, 0.2 * edge);
    for (Index i = 0; i < p.result.num_vertices(); ++i)
      for (int k = 0; k < 3; ++k) p.result.V(i, k) += offset(random);
    return p;
  }();
  return pair;
}

// Argument: TBB threads (0 = TBB's default, all cores).
tbb::global_control limit_threads(benchmark::State& state) {
  const auto threads = static_cast<std::size_t>(state.range(0));
  const auto max_threads = threads > 0 ? threads : static_cast<std::size_t>(tbb::info::default_concurrency());
  state.counters["tbb_threads"] = static_cast<double>(max_threads);
  return tbb::global_control(tbb::global_control::max_allowed_parallelism, max_threads);
}

// The target: both one-sided distances from scratch (sampling, trees, queries).
void BM_SymmetricDistance_100k(benchmark::State& state) {
  const Pair& p = meshes();
  const auto limit = limit_threads(state);
  for (auto _ : state) {
    const SymmetricDistance d = symmetric_distance(p.result.V, p.result.F, p.input.V, p.input.F);
    benchmark::DoNotOptimize(d.hausdorff);
  }
  state.counters["vertices"] = p.input.num_vertices();
}

// Everything compare_meshes reports (distances both ways, curvature of both meshes, surface
// curvature at the result's vertices, uniformity, quality), without a reference.
void BM_CompareMeshes_100k(benchmark::State& state) {
  const Pair& p = meshes();
  const auto limit = limit_threads(state);
  for (auto _ : state) {
    const MeshComparison c = compare_meshes(p.result, p.input, nullptr);
    benchmark::DoNotOptimize(c.result_input.hausdorff);
  }
}

// The parts, to see where the time goes.
void BM_SampleSurface_100k(benchmark::State& state) {
  const Pair& p = meshes();
  const auto limit = limit_threads(state);
  for (auto _ : state) {
    const SurfaceSamples s = sample_surface(p.result.V, p.result.F);
    benchmark::DoNotOptimize(s.points.data());
  }
}

void BM_BuildTree_100k(benchmark::State& state) {
  const Pair& p = meshes();
  const auto limit = limit_threads(state);
  for (auto _ : state) {
    const DistanceQuery query(p.input.V, p.input.F);
    benchmark::DoNotOptimize(&query);
  }
}

void BM_Queries_100k(benchmark::State& state) {
  const Pair& p = meshes();
  const auto limit = limit_threads(state);
  static const SurfaceSamples samples = sample_surface(p.result.V, p.result.F);
  static const DistanceQuery query(p.input.V, p.input.F);
  for (auto _ : state) {
    const DistanceStats d = one_sided_distance(samples, query);
    benchmark::DoNotOptimize(d.max);
  }
  state.SetItemsProcessed(state.iterations() * samples.points.rows());  // queries per second
}

BENCHMARK(BM_SymmetricDistance_100k)
    ->ArgName("tbb_threads")
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_CompareMeshes_100k)->ArgName("tbb_threads")->Arg(0)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_SampleSurface_100k)->ArgName("tbb_threads")->Arg(0)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_BuildTree_100k)->ArgName("tbb_threads")->Arg(0)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Queries_100k)->ArgName("tbb_threads")->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace vertexflow::bench

BENCHMARK_MAIN();
