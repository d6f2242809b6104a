// render_mesh + PNG encoding at 1600x1200 on a ~1.1M-face mesh (bunny.off subdivided 1-to-16)
// and on the ~2.2M-face test mesh (bench_support.h): plain (4x multisampling, the default),
// without anti-aliasing, and with curvature colour plus wireframe. Each run reports its parts
// as counters (seconds): prepare (topology, normals, colours, arrays), draw (OpenGL until
// glFinish), readback (multisample resolve, copy), png. llvmpipe uses LP_NUM_THREADS
// rasteriser threads (default: one per core); the counter lp_threads says what it was.
// Exaggerated shading (exaggerated_shading.h) is timed alone on horse-48k (96,966 faces, the
// brief's "100k faces in well under a second") and as a whole render on the 1M-face bunny.
//
//   build/bin/bench_render --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include "bench_support.h"

#include "vertexflow/exaggerated_shading.h"
#include "vertexflow/io.h"
#include "vertexflow/render.h"

#include <benchmark/benchmark.h>

#include <chrono>
#include <cstdlib>
#include <string>
#include <thread>

namespace vertexflow::bench {
namespace {

const Mesh& bunny_1m() {
  static const Mesh mesh = subdivide_uniform(read_mesh(data_dir() / "bunny.off"), 4);  // 1,114,656 faces
  return mesh;
}

const Mesh& large_2m() {
  static const Mesh mesh = make_large_test_mesh();
  return mesh;
}

// llvmpipe's rule: LP_NUM_THREADS if set, else one per core (capped at 16 or 32 depending on
// the Mesa version; irrelevant on the 2-core reference machine).
int llvmpipe_threads() {
  if (const char* env = std::getenv("LP_NUM_THREADS")) return std::atoi(env);
  return static_cast<int>(std::thread::hardware_concurrency());
}

void run(benchmark::State& state, const Mesh& mesh, RenderColor color, bool wireframe, int samples = 4,
         RenderShading shading = RenderShading::Smooth) {
  RenderOptions options;  // 1600x1200, iso view
  options.samples = samples;
  options.shading = shading;
  options.color = color;
  options.wireframe = wireframe;
  double prepare = 0, draw = 0, readback = 0, png = 0, bytes = 0;
  for (auto _ : state) {
    RenderInfo info;
    const Image image = render_mesh(mesh, options, &info);
    const auto start = std::chrono::steady_clock::now();
    const std::string encoded = encode_png(image);
    png += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    prepare += info.prepare_seconds;
    draw += info.draw_seconds;
    readback += info.readback_seconds;
    bytes = static_cast<double>(encoded.size());
    benchmark::DoNotOptimize(encoded.data());
  }
  const auto n = static_cast<double>(state.iterations());
  state.counters["faces"] = mesh.num_faces();
  state.counters["prepare_s"] = prepare / n;
  state.counters["draw_s"] = draw / n;
  state.counters["readback_s"] = readback / n;
  state.counters["png_s"] = png / n;
  state.counters["png_bytes"] = bytes;
  state.counters["lp_threads"] = llvmpipe_threads();
}

void BM_Render_1M(benchmark::State& state) {
  run(state, bunny_1m(), RenderColor::None, false);
}
void BM_RenderNoAntialiasing_1M(benchmark::State& state) {
  run(state, bunny_1m(), RenderColor::None, false, 1);
}
void BM_RenderMeanWireframe_1M(benchmark::State& state) {
  run(state, bunny_1m(), RenderColor::Mean, true);
}
void BM_Render_2M(benchmark::State& state) {
  run(state, large_2m(), RenderColor::None, false);
}
void BM_RenderExaggerated_1M(benchmark::State& state) {
  run(state, bunny_1m(), RenderColor::None, false, 4, RenderShading::Exaggerated);
}
void BM_ExaggeratedShading_Horse97k(benchmark::State& state) {
  static const Mesh horse = read_mesh(data_dir() / "horse-48k.ply");
  for (auto _ : state) {
    const Eigen::VectorXd shade = exaggerated_shading(horse.V, horse.F, Eigen::Vector3d(-1, 1, 1));
    benchmark::DoNotOptimize(shade.data());
  }
  state.counters["faces"] = horse.num_faces();
}

BENCHMARK(BM_Render_1M)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);
BENCHMARK(BM_RenderNoAntialiasing_1M)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);
BENCHMARK(BM_RenderMeanWireframe_1M)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);
BENCHMARK(BM_Render_2M)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);
BENCHMARK(BM_RenderExaggerated_1M)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);
BENCHMARK(BM_ExaggeratedShading_Horse97k)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(5);

}  // namespace
}  // namespace vertexflow::bench

BENCHMARK_MAIN();
