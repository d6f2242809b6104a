// Experiment harness (not a benchmark): fits a mesh to a dense reference (fit.h) with options
// given as key=value (spv wv fair rounds tol minq flow=0|1) and prints the two-sided distances
// to the reference (mean of both one-sided means, RMS over both, Hausdorff) before and after,
// relative to the input's, with the minimum quality and the guard's counts.
#include "vertexflow/distance.h"
#include "vertexflow/fit.h"
#include "vertexflow/flow.h"
#include "vertexflow/io.h"
#include "vertexflow/quality.h"
#include "vertexflow/timing.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

using namespace vertexflow;

namespace {

struct TwoSided {
  double mean, rms, hausdorff;
};

TwoSided two_sided(const Vertices& V, const Faces& F, const Mesh& reference) {
  SamplingOptions sampling;
  sampling.samples = 200000;
  const SymmetricDistance d = symmetric_distance(V, F, reference.V, reference.F, sampling);
  return {d.mean(), d.rms(), d.hausdorff};
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: fit_sweep COARSE DENSE [key=value ...]\n");
    return 2;
  }
  FitOptions o;
  bool flow_first = false;
  int smooth = 0;  // > 0: fit to the PN estimate of COARSE with this many segments, not to DENSE
  for (int a = 3; a < argc; ++a) {
    const std::string s = argv[a];
    const auto eq = s.find('=');
    const std::string k = s.substr(0, eq);
    const double v = std::atof(s.substr(eq + 1).c_str());
    if (k == "spv")
      o.samples_per_vertex = v;
    else if (k == "wv")
      o.mesh_to_reference_weight = v;
    else if (k == "fair")
      o.fairness = v;
    else if (k == "prox")
      o.proximity = v;
    else if (k == "rounds")
      o.max_rounds = static_cast<int>(v);
    else if (k == "tol")
      o.tolerance = v;
    else if (k == "minq")
      o.guard.min_quality = v;
    else if (k == "smooth")
      smooth = static_cast<int>(v);
    else if (k == "flow")
      flow_first = v != 0;
    else {
      std::fprintf(stderr, "unknown %s\n", k.c_str());
      return 2;
    }
  }
  const Mesh coarse = read_mesh(argv[1]);
  const Mesh dense = read_mesh(argv[2]);
  const auto start = std::chrono::steady_clock::now();
  Vertices start_V = coarse.V;
  if (flow_first) start_V = vertex_flow(coarse.V, coarse.F).V;
  SmoothSurfaceOptions pn;
  pn.segments = std::max(smooth, 1);
  const Mesh target = smooth > 0 ? smooth_surface_estimate(coarse.V, coarse.F, pn) : dense;
  const FitResult r = fit_to_reference(start_V, coarse.F, target.V, target.F, o);
  const double seconds = seconds_since(start);
  const TwoSided in = two_sided(coarse.V, coarse.F, dense), out = two_sided(r.V, coarse.F, dense);
  std::printf(
      "%s: mean %+.1f%% rms %+.1f%% haus %+.1f%% | qmin %.3f -> %.3f | rounds %d%s | flips %ld low %ld "
      "limited %ld | %.2f s (tree %.2f queries %.2f solve %.2f guard %.2f)\n",
      argv[1], 100 * (out.mean / in.mean - 1), 100 * (out.rms / in.rms - 1), 100 * (out.hausdorff / in.hausdorff - 1),
      triangle_quality(coarse.V, coarse.F).minCoeff(), triangle_quality(r.V, coarse.F).minCoeff(), r.report.rounds,
      r.report.converged ? " conv" : "", static_cast<long>(r.report.flipped_before_guard),
      static_cast<long>(r.report.low_quality_before_guard), static_cast<long>(r.report.limited_vertices), seconds,
      r.report.seconds_tree, r.report.seconds_queries, r.report.seconds_solve, r.report.seconds_guard);
  std::printf("  rms per round:");
  for (const double x : r.report.rms_distance) std::printf(" %.4g", x);
  std::printf("\n");
  return 0;
}
