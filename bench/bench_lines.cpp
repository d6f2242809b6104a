// `vertexflow lines` without file I/O (issue 17: a 100k-face mesh at 1600x1200 in at most 1 s):
// draw_lines (curvature and its derivative, every line type, the depth buffer, hidden-line
// removal) plus the SVG document, or plus the cairo strokes and PNG encoding, on horse-48k
// (96,966 faces) and amo (180,220 faces), iso view. Counters: the parts in seconds (lines,
// depth, visibility, output) and the number of visible pieces.
//
//   build/bin/bench_lines --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include "bench_support.h"

#include "vertexflow/io.h"
#include "vertexflow/line_drawing.h"

#include <benchmark/benchmark.h>

#include <chrono>
#include <string>

namespace vertexflow::bench {
namespace {

void run(benchmark::State& state, const char* file, bool png) {
  const Mesh mesh = read_mesh(data_dir() / file);
  LineDrawingOptions options;  // 1600x1200, iso view, every line type
  double lines = 0, depth = 0, visibility = 0, output = 0, pieces = 0;
  for (auto _ : state) {
    const LineDrawing drawing = draw_lines(mesh, options);
    const auto start = std::chrono::steady_clock::now();
    const std::string bytes = png ? encode_png(line_image(drawing)) : svg_document(drawing);
    benchmark::DoNotOptimize(bytes.data());
    output += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    lines += drawing.lines_seconds;
    depth += drawing.depth_seconds;
    visibility += drawing.visibility_seconds;
    pieces = static_cast<double>(drawing.lines.size());
  }
  const auto n = static_cast<double>(state.iterations());
  state.counters["lines"] = lines / n;
  state.counters["depth"] = depth / n;
  state.counters["visibility"] = visibility / n;
  state.counters["output"] = output / n;
  state.counters["pieces"] = pieces;
  state.counters["faces"] = static_cast<double>(mesh.F.rows());
}

BENCHMARK_CAPTURE(run, horse48k_svg, "horse-48k.ply", false)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(run, horse48k_png, "horse-48k.ply", true)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(run, amo_svg, "amo.off", false)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace vertexflow::bench

BENCHMARK_MAIN();
