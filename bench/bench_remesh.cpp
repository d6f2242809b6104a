// simplify (Garland-Heckbert through CGAL) of a ~1M-face mesh to 10 % of its faces, and
// remesh_to_vertex_count of the bundled bunny and armadillo to 6000 vertices (all runs of the
// edge-length search included), plus one fixed-length run to show the cost of a single run.
// Each iteration converts, processes and converts back; the input is read once.
//
//   build/bin/bench_remesh --benchmark_repetitions=3 --benchmark_report_aggregates_only=true
#include "bench_support.h"

#include "vertexflow/io.h"
#include "vertexflow/remesh.h"
#include "vertexflow/simplify.h"

#include <benchmark/benchmark.h>

#include <iostream>
#include <map>
#include <string>

namespace vertexflow::bench {
namespace {

// bunny.off (69,666 faces) split 1-to-16: 1,114,656 faces, 557,330 vertices, closed.
const Mesh& million_faces() {
  static const Mesh mesh = [] {
    Mesh m = subdivide_uniform(read_mesh(data_dir() / "bunny.off"), 4);
    report_topology(m, std::cerr);
    return m;
  }();
  return mesh;
}

const Mesh& bundled(const char* name) {
  static std::map<std::string, Mesh> meshes;
  auto it = meshes.find(name);
  if (it == meshes.end()) it = meshes.emplace(name, read_mesh(data_dir() / name)).first;
  return it->second;
}

void BM_Simplify_1M_To10Percent(benchmark::State& state) {
  const Mesh& mesh = million_faces();
  SimplifyOptions options;
  options.target_ratio = 0.1;
  Index faces = 0;
  for (auto _ : state) {
    SimplifyResult result = simplify(mesh.V, mesh.F, options);
    faces = result.mesh.num_faces();
    benchmark::DoNotOptimize(result.mesh.V.data());
  }
  state.counters["input_faces"] = mesh.num_faces();
  state.counters["output_faces"] = faces;
  state.SetItemsProcessed(state.iterations() * mesh.num_faces());  // input faces per second
}

void remesh_to_6k(benchmark::State& state, const char* name) {
  const Mesh& mesh = bundled(name);
  RemeshOptions options;
  options.target_vertices = 6000;
  RemeshReport report;
  Index vertices = 0;
  for (auto _ : state) {
    RemeshResult result = remesh_to_vertex_count(mesh.V, mesh.F, options);
    vertices = result.mesh.num_vertices();
    report = result.report;
    benchmark::DoNotOptimize(result.mesh.V.data());
  }
  state.counters["input_vertices"] = mesh.num_vertices();
  state.counters["vertices"] = vertices;
  state.counters["runs"] = static_cast<double>(report.attempts.size());
}

void remesh_one_run(benchmark::State& state, const char* name) {
  const Mesh& mesh = bundled(name);
  // The equilateral estimate for 6000 vertices (remesh.h); one run at that length.
  double area = 0;
  for (Index f = 0; f < mesh.num_faces(); ++f) area += face_area(mesh.V, mesh.F, f);
  const double length = edge_length_for_vertex_count(area, 6000);
  Index vertices = 0;
  for (auto _ : state) {
    Mesh result = remesh_isotropic(mesh.V, mesh.F, length);
    vertices = result.num_vertices();
    benchmark::DoNotOptimize(result.V.data());
  }
  state.counters["vertices"] = vertices;
}

BENCHMARK(BM_Simplify_1M_To10Percent)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1);
BENCHMARK_CAPTURE(remesh_to_6k, bunny, "bunny.off")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1);
BENCHMARK_CAPTURE(remesh_to_6k, armadillo, "armadillo-43k.obj")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(1);
BENCHMARK_CAPTURE(remesh_one_run, bunny, "bunny.off")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1);
BENCHMARK_CAPTURE(remesh_one_run, armadillo, "armadillo-43k.obj")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(1);

}  // namespace
}  // namespace vertexflow::bench

BENCHMARK_MAIN();
