// Mesh distances and compare_meshes on two ~100k-vertex meshes with 200,000 samples per mesh.
//
// The meshes: data/fertility.off (4,494 vertices, closed, genus 4) subdivided 1-to-25
// (bench_support.h): 112,494 vertices and 225,000 faces ("input"), and a smoothly deformed copy ("result": the
// same connectivity, like a result of the flow): every vertex moved by
// 0.3 h (sin(2 pi y / L + 1), sin(2 pi z / L + 2), sin(2 pi x / L + 3)), h the mean edge length
// and L = 30 h, so neighbouring vertices move alike, as the flow moves them. Each distance
// direction measures 200,000 area samples plus 112k vertices plus 337k edge midpoints.
//
//   build/bin/bench_compare --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include "bench_support.h"

#include "vertexflow/compare.h"
#include "vertexflow/distance.h"
#include "vertexflow/io.h"

#include <benchmark/benchmark.h>
#include <tbb/global_control.h>
#include <tbb/info.h>

#include <cmath>
#include <iostream>

namespace vertexflow::bench {
namespace {

struct Pair {
  Mesh input;
  Mesh result;
};

const Pair& meshes() {
  static const Pair pair = [] {
    Pair p;
    p.input = subdivide_uniform(read_mesh(data_dir() / "fertility.off"), 5);
    report_topology(p.input, std::cerr);
    const double edge = mean_edge_length(p.input.V, build_topology(p.input.F, p.input.num_vertices()));
    p.result = p.input;
    const double wavelength = 30 * edge, pi = 3.14159265358979323846;
    for (Index i = 0; i < p.result.num_vertices(); ++i) {
      const Eigen::Vector3d v = p.input.V.row(i).transpose() * (2 * pi / wavelength);
      p.result.V.row(i) +=
          0.3 * edge * Eigen::RowVector3d(std::sin(v.y() + 1), std::sin(v.z() + 2), std::sin(v.x() + 3));
    }
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
BENCHMARK(BM_CompareMeshes_100k)->ArgName("tbb_threads")->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_SampleSurface_100k)->ArgName("tbb_threads")->Arg(0)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_BuildTree_100k)->ArgName("tbb_threads")->Arg(0)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Queries_100k)->ArgName("tbb_threads")->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace vertexflow::bench

BENCHMARK_MAIN();
