// vertex_flow on the meshes of the paper's Table 1 (ours where the paper's are not public),
// plus a ~100k-vertex mesh and the ~1M-vertex test mesh (bench_support.h). Each case reports
// the phases of FlowReport as counters (milliseconds per run), the solver used and its
// iterations, the process CPU time per run (both threads; the machine is shared, so compare
// variants by it), vertices per second, and the process's peak resident set size.
//
//   build/bin/bench_flow --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
//   build/bin/bench_flow --benchmark_filter='1M' --benchmark_repetitions=5   # own process: peak RSS
//
// "pipeline_ms" is curvature + assembly + factorisation + solve, the part the targets
// are about (no I/O, no projection, no guard). Cases named .../direct, .../iterative and
// .../multilevel force the solver, to compare the paths; the others use
// LinearSolver::Automatic. Cases named .../density-30 add 30 density passes
// (FlowOptions::density); "density_ms" is their time.
//
// Cases named operator/... time one product H x of the solve's operator (flow_operator.h) on
// the mesh's first frame, the conjugate gradients' inner step, so that a change to the passes
// is measured without the rest of the flow's noise:
//   build/bin/bench_flow --benchmark_filter='operator/' --benchmark_repetitions=5
#include "bench_support.h"
#include "flow_operator.h"
#include "flow_setup.h"
#include "flow_terms.h"
#include "numerics/vertex_ordering.h"

#include "vertexflow/flow.h"
#include "vertexflow/io.h"

#include <CGAL/Simple_cartesian.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/Count_stop_predicate.h>
#include <CGAL/Surface_mesh_simplification/edge_collapse.h>
#include <benchmark/benchmark.h>
#include <sys/resource.h>

#include <functional>
#include <iostream>
#include <map>
#include <string>

namespace vertexflow::bench {
namespace {

double process_cpu_seconds() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
         1e-6 * static_cast<double>(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
}

double peak_rss_megabytes() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;  // ru_maxrss is in KiB on Linux
}

// horse-48k decimated to ~10k vertices (no decimated copy is bundled): CGAL's edge collapse
// with its default (Lindstrom-Turk) cost and placement, stopped at 3 x 10,000 edges.
Mesh decimated_horse() {
  using Kernel = CGAL::Simple_cartesian<double>;
  using SurfaceMesh = CGAL::Surface_mesh<Kernel::Point_3>;
  const Mesh input = read_mesh(data_dir() / "horse-48k.ply");
  SurfaceMesh sm;
  std::vector<SurfaceMesh::Vertex_index> handles;
  for (Index v = 0; v < input.num_vertices(); ++v)
    handles.push_back(sm.add_vertex(Kernel::Point_3(input.V(v, 0), input.V(v, 1), input.V(v, 2))));
  for (Index f = 0; f < input.num_faces(); ++f)
    sm.add_face(handles[static_cast<std::size_t>(input.F(f, 0))], handles[static_cast<std::size_t>(input.F(f, 1))],
                handles[static_cast<std::size_t>(input.F(f, 2))]);
  CGAL::Surface_mesh_simplification::Count_stop_predicate<SurfaceMesh> stop(30000);
  CGAL::Surface_mesh_simplification::edge_collapse(sm, stop);
  sm.collect_garbage();
  Mesh out;
  out.V.resize(static_cast<Eigen::Index>(sm.number_of_vertices()), 3);
  for (const auto v : sm.vertices()) {
    const auto& p = sm.point(v);
    out.V.row(static_cast<Eigen::Index>(v.idx())) << p.x(), p.y(), p.z();
  }
  out.F.resize(static_cast<Eigen::Index>(sm.number_of_faces()), 3);
  for (const auto f : sm.faces()) {
    int k = 0;
    for (const auto v : CGAL::vertices_around_face(sm.halfedge(f), sm))
      out.F(static_cast<Eigen::Index>(f.idx()), k++) = static_cast<Index>(v.idx());
  }
  return out;
}

const Mesh& mesh(const std::string& name) {
  static std::map<std::string, Mesh> cache;
  auto it = cache.find(name);
  if (it != cache.end()) return it->second;
  Mesh m;
  if (name == "horse-10k") {
    m = decimated_horse();
  } else if (name == "armadillo-1M") {
    m = make_large_test_mesh();
  } else {
    m = read_mesh(data_dir() / name);
  }
  report_topology(m, std::cerr);
  return cache.emplace(name, std::move(m)).first->second;
}

void run(benchmark::State& state, const std::string& name, LinearSolver solver, int density_passes = 0) {
  const Mesh& input = mesh(name);
  FlowOptions options;
  options.solver = solver;
  options.density.passes = density_passes;
  FlowReport sum;
  double cpu = 0;
  int iterations = 0;
  for (auto _ : state) {
    const double cpu_start = process_cpu_seconds();
    const FlowResult result = vertex_flow(input.V, input.F, options);
    cpu += process_cpu_seconds() - cpu_start;
    benchmark::DoNotOptimize(result.V.data());
    const FlowReport& r = result.report;
    sum.seconds_curvature += r.seconds_curvature;
    sum.seconds_assembly += r.seconds_assembly;
    sum.seconds_factorization += r.seconds_factorization;
    sum.seconds_solve += r.seconds_solve;
    sum.seconds_projection += r.seconds_projection;
    sum.seconds_guard += r.seconds_guard;
    sum.seconds_density += r.seconds_density;
    sum.solver_used = r.solver_used;
    sum.solver_iterations = r.solver_iterations;
    sum.solver_error = r.solver_error;
    ++iterations;
  }
  const double per_run_ms = 1000.0 / std::max(iterations, 1);
  state.counters["vertices"] = static_cast<double>(input.num_vertices());
  state.counters["curvature_ms"] = sum.seconds_curvature * per_run_ms;
  state.counters["assembly_ms"] = sum.seconds_assembly * per_run_ms;
  state.counters["factorization_ms"] = sum.seconds_factorization * per_run_ms;
  state.counters["solve_ms"] = sum.seconds_solve * per_run_ms;
  state.counters["projection_ms"] = sum.seconds_projection * per_run_ms;
  state.counters["guard_ms"] = sum.seconds_guard * per_run_ms;
  if (density_passes > 0) state.counters["density_ms"] = sum.seconds_density * per_run_ms;
  state.counters["pipeline_ms"] =
      (sum.seconds_curvature + sum.seconds_assembly + sum.seconds_factorization + sum.seconds_solve) * per_run_ms;
  state.counters["process_cpu_ms"] = cpu * per_run_ms;
  state.counters["direct"] = sum.solver_used == LinearSolver::Direct ? 1 : 0;
  state.counters["multilevel"] = sum.solver_used == LinearSolver::Multilevel ? 1 : 0;
  state.counters["cg_iterations"] = sum.solver_iterations;
  state.counters["residual"] = sum.solver_error;
  state.counters["peak_rss_MB"] = peak_rss_megabytes();
  state.SetItemsProcessed(state.iterations() * input.num_vertices());  // vertices per second
}

// The solve's operator on `name`'s first frame (as FlowSystemSolver numbers the vertices),
// applied to the normalised right-hand side, with its caches in `precision` (the iterations'
// products use Float at the default tolerance: flow_operator.h).
void run_operator(benchmark::State& state, const std::string& name, FlowOperator::CachePrecision precision) {
  const Mesh& input = mesh(name);
  const Topology topology = build_topology(input.F, input.num_vertices());
  const FlowOptions options;
  const FlowSetup setup = prepare_flow(input.V, input.F, topology, options);
  const FlowFrame frame = flow_frame(setup.input, input.F, topology, options, setup.sliver_faces);
  const FlowTerms terms = make_flow_terms(topology, setup.fixed, frame, options.weights,
                                          breadth_first_order(topology, space_filling_order(frame.P)));
  FlowOperator op(terms);
  const BlockVector b = op.right_hand_side(to_local(terms, frame.P.data()));
  const BlockVector x = b / b.norm();
  op.use_cache_precision(precision);
  BlockVector y(x.size());
  op.apply(x, y);  // the caches' first touch outside the loop
  for (auto _ : state) benchmark::DoNotOptimize(op.apply(x, y));
  state.counters["vertices"] = static_cast<double>(input.num_vertices());
  state.SetItemsProcessed(state.iterations() * input.num_vertices());
}

void register_cases() {
  for (const std::string name : {"bunny_uniform.off", "amo.off", "armadillo-1M"})
    for (const auto& [suffix, precision] : {std::pair{"", FlowOperator::CachePrecision::Double},
                                            std::pair{"/float", FlowOperator::CachePrecision::Float}})
      benchmark::RegisterBenchmark(("operator/" + name + suffix).c_str(),
                                   [name, precision](benchmark::State& state) { run_operator(state, name, precision); })
          ->Unit(benchmark::kMillisecond)
          ->UseRealTime();
  // Table 1's meshes (torus, Max-Planck, spot, fandisk, horse at ~10k, bunny, armadillo), amo
  // (90k) as the ~100k case, the subdivided armadillo as the ~1M case.
  const std::vector<std::string> table = {"torus.obj",         "max-planck-5k.obj", "spot.obj",
                                          "fandisk.off",       "horse-10k",         "bunny_uniform.off",
                                          "armadillo-43k.obj", "amo.off",           "armadillo-1M"};
  for (const std::string& name : table) {
    const bool large = name == "amo.off" || name == "armadillo-1M";
    auto* automatic = benchmark::RegisterBenchmark(
        ("flow/" + name).c_str(), [name](benchmark::State& state) { run(state, name, LinearSolver::Automatic); });
    automatic->Unit(benchmark::kMillisecond)->UseRealTime();
    if (large) automatic->Iterations(1);
    // FlowOptions::density: 30 passes (what reaches rho +0.2 on the vertex-clustered bunnies).
    if (name == "horse-10k" || name == "amo.off" || name == "armadillo-1M") {
      auto* passes = benchmark::RegisterBenchmark(
          ("flow/" + name + "/density-30").c_str(),
          [name](benchmark::State& state) { run(state, name, LinearSolver::Automatic, 30); });
      passes->Unit(benchmark::kMillisecond)->UseRealTime();
      if (large) passes->Iterations(1);
    }
    if (name == "armadillo-1M") continue;  // the coupled factorisation does not fit (16 GB)
    for (const LinearSolver forced : {LinearSolver::Direct, LinearSolver::Iterative, LinearSolver::Multilevel}) {
      const std::string suffix = forced == LinearSolver::Direct      ? "/direct"
                                 : forced == LinearSolver::Iterative ? "/iterative"
                                                                     : "/multilevel";
      auto* b = benchmark::RegisterBenchmark(("flow/" + name + suffix).c_str(),
                                             [name, forced](benchmark::State& state) { run(state, name, forced); });
      b->Unit(benchmark::kMillisecond)->UseRealTime();
      if (large) b->Iterations(1);
    }
  }
}

}  // namespace
}  // namespace vertexflow::bench

int main(int argc, char** argv) {
  vertexflow::bench::register_cases();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
