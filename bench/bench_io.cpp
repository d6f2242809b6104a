// Read and write times of the ~1M-vertex test mesh (bench_support.h) in every format.
//
// The files are written once, before the first case runs, to a temporary folder
// ($VERTEXFLOW_BENCH_DIR if set, else <tmp>/vertexflow-bench-PID), which is removed at exit.
// Reads therefore come from the page cache; writes include the fsync of write_mesh's atomic
// replacement.
//
//   build/bin/bench_io --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
//
// read/comb_polygon/N reads an OBJ, held in memory, whose only face is a comb-shaped simple
// polygon of N corners (issue 12: its triangulation was quadratic, 31 s for 100k corners):
//
//   build/bin/bench_io --benchmark_filter=comb
#include "bench_support.h"

#include "vertexflow/io.h"

#include <benchmark/benchmark.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace vertexflow::bench {
namespace {

struct Format {
  const char* name;      // benchmark name suffix
  const char* filename;  // extension selects the format
  WriteOptions options;
};

WriteOptions with(void (*set)(WriteOptions&)) {
  WriteOptions o;
  set(o);
  return o;
}

const std::vector<Format>& formats() {
  static const std::vector<Format> list = {
      {"ply_binary_le_double", "mesh_double.ply", {}},
      {"ply_binary_le_float", "mesh_float.ply", with([](WriteOptions& o) { o.ply_double_precision = false; })},
      {"ply_ascii", "mesh_ascii.ply", with([](WriteOptions& o) { o.ply_encoding = PlyEncoding::Ascii; })},
      {"obj", "mesh.obj", {}},
      {"off_ascii", "mesh_ascii.off", {}},
      {"off_binary", "mesh_binary.off", with([](WriteOptions& o) { o.off_binary = true; })},
      {"stl_binary", "mesh_binary.stl", {}},
      {"stl_ascii", "mesh_ascii.stl", with([](WriteOptions& o) { o.stl_binary = false; })},
      {"ply_gz", "mesh_double.ply.gz", {}},  // binary little-endian, double, gzip level 6
  };
  return list;
}

// The test mesh and one file per format, created on first use.
struct Fixture {
  std::filesystem::path dir;
  bool own_dir = false;  // created here, so removed entirely at exit
  Mesh mesh;

  Fixture() {
    if (const char* env = std::getenv("VERTEXFLOW_BENCH_DIR"); env && *env) {
      dir = env;
    } else {
      dir = std::filesystem::temp_directory_path() / ("vertexflow-bench-" + std::to_string(::getpid()));
    }
    own_dir = std::filesystem::create_directories(dir);
    mesh = make_large_test_mesh();
    report_topology(mesh, std::cerr);
    for (const Format& format : formats()) {
      const auto path = dir / format.filename;
      write_mesh(path, mesh, format.options);
      std::cerr << "wrote " << path.string() << " (" << std::filesystem::file_size(path) << " bytes)\n";
    }
  }
  Fixture(const Fixture&) = delete;
  Fixture& operator=(const Fixture&) = delete;
  ~Fixture() {
    std::error_code ec;
    if (own_dir) {
      std::filesystem::remove_all(dir, ec);
      return;
    }
    for (const Format& format : formats()) std::filesystem::remove(dir / format.filename, ec);
  }
};

std::unique_ptr<Fixture> g_fixture;

Fixture& fixture() {
  if (!g_fixture) g_fixture = std::make_unique<Fixture>();
  return *g_fixture;
}

void read_case(benchmark::State& state, const Format* format) {
  const auto path = fixture().dir / format->filename;
  const auto bytes = static_cast<std::int64_t>(std::filesystem::file_size(path));
  Index vertices = 0, faces = 0;
  for (auto _ : state) {
    Mesh mesh = read_mesh(path);
    vertices = mesh.num_vertices();
    faces = mesh.num_faces();
    benchmark::DoNotOptimize(mesh.V.data());
    benchmark::DoNotOptimize(mesh.F.data());
    benchmark::ClobberMemory();
  }
  state.SetBytesProcessed(state.iterations() * bytes);
  state.counters["file_MB"] = static_cast<double>(bytes) / 1e6;
  state.counters["vertices"] = vertices;
  state.counters["faces"] = faces;
}

void write_case(benchmark::State& state, const Format* format) {
  Fixture& f = fixture();
  const auto path = f.dir / (std::string("out_") + format->filename);
  for (auto _ : state) {
    write_mesh(path, f.mesh, format->options);
    benchmark::ClobberMemory();
  }
  const auto bytes = static_cast<std::int64_t>(std::filesystem::file_size(path));
  state.SetBytesProcessed(state.iterations() * bytes);
  state.counters["file_MB"] = static_cast<double>(bytes) / 1e6;
  std::filesystem::remove(path);
}

// One OBJ face, a comb with N / 4 teeth of width 1 and length N / 4 leaning sideways by N / 16,
// so that each long edge runs past O(N) corners (tests/io/test_triangulate.cpp uses the same).
std::string comb_obj(int corners) {
  const int teeth = corners / 4;
  const double height = teeth, lean = corners / 16.0;
  std::vector<std::pair<double, double>> points = {{0, 0}, {2.0 * teeth - 1, 0}};
  for (int k = teeth - 1; k >= 0; --k) {
    points.insert(points.end(), {{2.0 * k + 1 + lean, height}, {2.0 * k + lean, height}});
    if (k > 0) points.insert(points.end(), {{2.0 * k, 1}, {2.0 * k - 1, 1}});
  }
  std::string obj;
  for (const auto& [x, y] : points) obj += "v " + std::to_string(x) + ' ' + std::to_string(y) + " 0\n";
  obj += 'f';
  for (std::size_t i = 1; i <= points.size(); ++i) obj += ' ' + std::to_string(i);
  obj += '\n';
  return obj;
}

void read_comb_case(benchmark::State& state) {
  const std::string obj = comb_obj(static_cast<int>(state.range(0)));
  Index faces = 0;
  for (auto _ : state) {
    Mesh mesh = read_mesh_from_memory(obj, MeshFormat::Obj, "comb.obj");
    faces = mesh.num_faces();
    benchmark::DoNotOptimize(mesh.F.data());
    benchmark::ClobberMemory();
  }
  state.counters["faces"] = faces;
}

void register_cases() {
  for (const Format& format : formats()) {
    benchmark::RegisterBenchmark((std::string("read/") + format.name).c_str(), read_case, &format)
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
  }
  for (const Format& format : formats()) {
    benchmark::RegisterBenchmark((std::string("write/") + format.name).c_str(), write_case, &format)
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
  }
  benchmark::RegisterBenchmark("read/comb_polygon", read_comb_case)
      ->Arg(12500)
      ->Arg(25000)
      ->Arg(50000)
      ->Arg(100000)
      ->Unit(benchmark::kMillisecond)
      ->UseRealTime();
}

}  // namespace
}  // namespace vertexflow::bench

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  vertexflow::bench::register_cases();
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  vertexflow::bench::g_fixture.reset();  // removes the files
  return 0;
}
