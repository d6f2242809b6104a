// html_report (include/vertexflow/html_report.h): the whole page for bunny_uniform (8.9k
// vertices, drawn in full) and for the ~1M-vertex test mesh (2.16M faces, decimated for display
// to 1M faces by default). The "result" is the input with every vertex moved by a smooth field,
// so curvature, quality and displacement are all non-trivial. Reports the page size.
//
//   build/bin/bench_html_report --benchmark_repetitions=3 --benchmark_report_aggregates_only=true
#include "bench_support.h"

#include "vertexflow/html_report.h"
#include "vertexflow/io.h"

#include <benchmark/benchmark.h>

#include <cmath>

namespace vertexflow::bench {
namespace {

struct Pair {
  Mesh input, result;
};

Pair make_pair(Mesh mesh) {
  Pair p{std::move(mesh), {}};
  p.result = p.input;
  const double scale = bounding_box(p.input.V).diagonal();
  for (Index v = 0; v < p.input.num_vertices(); ++v)
    p.result.V(v, 1) += 1e-3 * scale * std::sin(20 * p.input.V(v, 0) / scale);
  return p;
}

const Pair& bunny() {
  static const Pair p = make_pair(read_mesh(data_dir() / "bunny_uniform.off"));
  return p;
}

const Pair& large() {
  static const Pair p = make_pair(make_large_test_mesh());
  return p;
}

void run(benchmark::State& state, const Pair& p) {
  std::size_t bytes = 0;
  for (auto _ : state) {
    const std::string html = html_report(p.input, p.result, R"({"note": "benchmark"})");
    bytes = html.size();
    benchmark::DoNotOptimize(html.data());
  }
  state.counters["faces"] = p.input.num_faces();
  state.counters["page_MB"] = static_cast<double>(bytes) / 1e6;
}

void BM_HtmlReport_BunnyUniform(benchmark::State& state) {
  run(state, bunny());
}
void BM_HtmlReport_1M(benchmark::State& state) {
  run(state, large());
}

BENCHMARK(BM_HtmlReport_BunnyUniform)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_HtmlReport_1M)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1);

}  // namespace
}  // namespace vertexflow::bench

BENCHMARK_MAIN();
