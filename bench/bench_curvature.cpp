// principal_curvatures (normals + areas + face tensors + transport + diagonalisation) on the
// ~1M-vertex test mesh (bench_support.h), on the same mesh with its vertices numbered in face
// order, and on armadillo-43k, with TBB allowed all cores and limited to one thread. The
// topology is built once outside the timing loop; a second case includes it.
//
//   build/bin/bench_curvature --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include "bench_support.h"

#include "vertexflow/curvature.h"
#include "vertexflow/io.h"

#include <benchmark/benchmark.h>
#include <tbb/global_control.h>
#include <tbb/info.h>

#include <iostream>
#include <vector>

namespace vertexflow::bench {
namespace {

struct Input {
  Mesh mesh;
  Topology topology;
};

const Input& large_input() {
  static const Input input = [] {
    Input in{make_large_test_mesh(), {}};
    in.topology = build_topology(in.mesh.F, in.mesh.num_vertices());
    return in;
  }();
  return input;
}

// The same mesh with its vertices numbered in order of first use by the faces, as many scanners
// and remeshers write them: neighbouring vertices and faces then sit near each other in memory,
// unlike the test mesh's own order (original vertices, then edge points, then face points).
const Input& large_input_face_ordered() {
  static const Input input = [] {
    const Mesh& mesh = large_input().mesh;
    std::vector<Index> new_index(static_cast<std::size_t>(mesh.num_vertices()), -1);
    Index next = 0;
    Input in;
    in.mesh.F.resize(mesh.num_faces(), 3);
    for (Index f = 0; f < mesh.num_faces(); ++f) {
      for (int k = 0; k < 3; ++k) {
        Index& index = new_index[static_cast<std::size_t>(mesh.F(f, k))];
        if (index < 0) index = next++;
        in.mesh.F(f, k) = index;
      }
    }
    in.mesh.V.resize(mesh.num_vertices(), 3);
    for (Index v = 0; v < mesh.num_vertices(); ++v)
      in.mesh.V.row(new_index[static_cast<std::size_t>(v)]) = mesh.V.row(v);
    in.topology = build_topology(in.mesh.F, in.mesh.num_vertices());
    return in;
  }();
  return input;
}

const Input& armadillo() {
  static const Input input = [] {
    Input in{read_mesh(data_dir() / "armadillo-43k.obj"), {}};
    in.topology = build_topology(in.mesh.F, in.mesh.num_vertices());
    return in;
  }();
  return input;
}

void run(benchmark::State& state, const Input& input, bool with_topology) {
  const auto threads = static_cast<std::size_t>(state.range(0));
  const auto max_threads = threads > 0 ? threads : static_cast<std::size_t>(tbb::info::default_concurrency());
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, max_threads);
  for (auto _ : state) {
    Curvature c = with_topology ? principal_curvatures(input.mesh.V, input.mesh.F)
                                : principal_curvatures(input.mesh.V, input.mesh.F, input.topology);
    benchmark::DoNotOptimize(c.k1.data());
    benchmark::ClobberMemory();
  }
  state.counters["vertices"] = input.mesh.num_vertices();
  state.counters["tbb_threads"] = static_cast<double>(max_threads);
  state.SetItemsProcessed(state.iterations() * input.mesh.num_vertices());  // vertices per second
}

void BM_Curvature_1M(benchmark::State& state) {
  run(state, large_input(), false);
}
void BM_CurvatureWithTopology_1M(benchmark::State& state) {
  run(state, large_input(), true);
}
void BM_Curvature_1M_FaceOrdered(benchmark::State& state) {
  run(state, large_input_face_ordered(), false);
}
void BM_Curvature_Armadillo43k(benchmark::State& state) {
  run(state, armadillo(), false);
}

BENCHMARK(BM_Curvature_1M)->ArgName("tbb_threads")->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Curvature_1M_FaceOrdered)
    ->ArgName("tbb_threads")
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_CurvatureWithTopology_1M)->ArgName("tbb_threads")->Arg(0)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Curvature_Armadillo43k)
    ->ArgName("tbb_threads")
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace vertexflow::bench

BENCHMARK_MAIN();
