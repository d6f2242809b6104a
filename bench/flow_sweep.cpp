// Experiment harness (not a benchmark; docs/benchmarks.md does not use it): runs vertex_flow on
// meshes with options given as key=value (lambda mu dp eps iters proj fa minq fair) and prints
// the acceptance figures of the quality issue, one line per mesh, from compare_meshes.
#include "vertexflow/compare.h"
#include "vertexflow/curvature.h"
#include "vertexflow/flow.h"
#include "vertexflow/io.h"
#include "vertexflow/metrics.h"
#include "vertexflow/quality.h"
#include "vertexflow/topology.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

using namespace vertexflow;

int main(int argc, char** argv) {
  FlowOptions o;
  std::vector<std::string> meshes;
  for (int a = 1; a < argc; ++a) {
    std::string s = argv[a];
    const auto eq = s.find('=');
    if (eq == std::string::npos) {
      meshes.push_back(s);
      continue;
    }
    const std::string k = s.substr(0, eq);
    const double v = std::atof(s.substr(eq + 1).c_str());
    if (k == "lambda")
      o.weights.lambda = v;
    else if (k == "mu")
      o.weights.mu = v;
    else if (k == "dp")
      o.d_percentile = v;
    else if (k == "eps")
      o.weights.epsilon = v;
    else if (k == "iters")
      o.iterations = static_cast<int>(v);
    else if (k == "proj")
      o.project_to_input = v != 0;
    else if (k == "fa")
      o.feature_angle = v;
    else if (k == "minq")
      o.guard.min_quality = v;
    else if (k == "csmooth")
      o.curvature.smoothing_rounds = static_cast<int>(v);
    else if (k == "dpasses")
      o.density.passes = static_cast<int>(v);
    else if (k == "dexp")
      o.density.exponent = v;
    else if (k == "deps")
      o.density.epsilon = v;
    else if (k == "dstep")
      o.density.step = v;
    else if (k == "fair")
      o.weights.fairness_target = v != 0 ? FairnessTarget::InputNormal : FairnessTarget::Zero;
    else {
      std::fprintf(stderr, "unknown %s\n", k.c_str());
      return 2;
    }
  }
  for (const auto& path : meshes) {
    const Mesh in = read_mesh(path);
    const FlowResult r = vertex_flow(in.V, in.F, o);
    Mesh out = in;
    out.V = r.V;
    const MeshComparison c = compare_meshes(out, in, nullptr);
    const double unit = r.report.mean_edge_length;
    const Eigen::VectorXd qi = triangle_quality(in.V, in.F), qo = triangle_quality(out.V, in.F);
    double minq = 1;
    Index good = 0, below = 0;
    for (Index f = 0; f < in.num_faces(); ++f) {
      if (qi[f] >= 0.5) {
        ++good;
        minq = std::min(minq, qo[f]);
        below += qo[f] < 0.3;
      }
    }
    const double vb = signed_volume(in.V, in.F), va = signed_volume(out.V, in.F);
    const double cvi = c.edge_error_input.coefficient_of_variation, cvo = c.edge_error_result.coefficient_of_variation;
    std::vector<double> change;
    for (Index f = 0; f < in.num_faces(); ++f) {
      const double a0 = face_area(in.V, in.F, f), a1 = face_area(out.V, in.F, f);
      if (a0 > 0 && a1 > 0) change.push_back(std::abs(std::log(a1 / a0)));
    }
    std::sort(change.begin(), change.end());
    // Does the flow move the density the way |k1|+|k2| asks? Spearman between the per-vertex change
    // of log density and the change the isotropic ideal (density proportional to k) asks for.
    const Eigen::VectorXd din = vertex_density(in.V, in.F), dout = vertex_density(out.V, in.F);
    const Eigen::VectorXd kin =
        principal_curvatures(in.V, in.F, build_topology(in.F, in.num_vertices())).absolute_sum();
    Eigen::VectorXd got(in.num_vertices()), want(in.num_vertices());
    for (Index i = 0; i < in.num_vertices(); ++i) {
      got[i] = std::log(std::max(dout[i], 1e-300) / std::max(din[i], 1e-300));
      want[i] = std::log(std::max(kin[i], 1e-12)) - std::log(std::max(din[i], 1e-300));
    }
    std::printf("  [direction: spearman(dlog density, ideal dlog density) %.3f]\n", spearman_correlation(got, want));
    const std::string name = path.substr(path.find_last_of('/') + 1);
    std::printf(
        "%-20s rho %.3f -> %.3f (%+.3f)  CV %.3f -> %.3f (%+.1f%%)  minq %.3f below %.3f%%  drift %.4f  vol %+.3f%%  "
        "flip %ld degen %ld fixed %ld limited %ld lowq_bg %ld disp %.3f dA %.2f/%.2f\n",
        name.c_str(), c.redistribution_rho_input, c.redistribution_rho_result,
        c.redistribution_rho_result - c.redistribution_rho_input, cvi, cvo, 100 * (cvo - cvi) / cvi, minq,
        good ? 100.0 * below / good : 0.0, c.result_input.a_to_b.mean / unit,
        vb != 0 ? 100 * (va - vb) / std::abs(vb) : 0.0, static_cast<long>(c.flipped_faces.value_or(0)),
        static_cast<long>(c.degenerate_faces_result), static_cast<long>(r.report.fixed_vertices),
        static_cast<long>(r.report.limited_vertices), static_cast<long>(r.report.low_quality_before_guard),
        (r.V - in.V).rowwise().norm().mean() / unit, change[change.size() / 2], change[change.size() * 9 / 10]);
    std::fflush(stdout);
  }
}
