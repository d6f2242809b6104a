// Experiment (not a benchmark): what Spearman rho(|k1|+|k2|, 1/A_i) could an idealised
// redistribution reach on a mesh's connectivity? Prints, per mesh, the input's rho, the rho of
// face areas set to 1 / (mean |k1|+|k2| of the corners) and to 1 / sqrt(|k1 k2|), the rho
// between k and its one-ring mean (the estimator-noise ceiling), and log-linear blends from the
// input's areas to the first ideal with how much each face's area would have to change.
//
//   build/bin/flow_ideal data/max-planck-5k.obj
#include "vertexflow/curvature.h"
#include "vertexflow/io.h"
#include "vertexflow/metrics.h"
#include "vertexflow/topology.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

using namespace vertexflow;

int main(int argc, char** argv) {
  for (int a = 1; a < argc; ++a) {
    const Mesh m = read_mesh(argv[a]);
    const Topology t = build_topology(m.F, m.num_vertices());
    const Curvature c = principal_curvatures(m.V, m.F, t);
    const Eigen::VectorXd k = c.absolute_sum();
    const Index n = m.num_vertices();
    auto density_from_face_areas = [&](const Eigen::VectorXd& area) {
      Eigen::VectorXd A = Eigen::VectorXd::Zero(n);
      for (Index f = 0; f < m.num_faces(); ++f)
        for (int j = 0; j < 3; ++j) A[m.F(f, j)] += area[f] / 3;
      return Eigen::VectorXd(A.cwiseInverse());
    };
    // Ideal isotropic: face area proportional to 1 / (mean k of its corners) (uniform k L^2).
    Eigen::VectorXd iso(m.num_faces()), gauss(m.num_faces()), mixed(m.num_faces());
    for (Index f = 0; f < m.num_faces(); ++f) {
      double kk = 0, g = 0;
      for (int j = 0; j < 3; ++j) {
        kk += k[m.F(f, j)] / 3;
        g += std::sqrt(std::abs(c.k1[m.F(f, j)] * c.k2[m.F(f, j)])) / 3;
      }
      iso[f] = 1.0 / std::max(kk, 1e-12);
      gauss[f] = 1.0 / std::max(g, 1e-12);
    }
    // 1-ring mean of k (how much of k varies from one vertex to the next).
    Eigen::VectorXd smooth(n);
    for (Index i = 0; i < n; ++i) {
      const auto [b, e] = t.ring(i);
      double s = k[i];
      for (const Index* j = b; j != e; ++j) s += k[*j];
      smooth[i] = s / double(e - b + 1);
    }
    // Blends between the input's face areas and the ideal (log-linear), and how much each face
    // would have to change its area.
    Eigen::VectorXd a_in(m.num_faces());
    for (Index f = 0; f < m.num_faces(); ++f) a_in[f] = face_area(m.V, m.F, f);
    const double scale_ideal = a_in.sum() / iso.sum();
    for (double tb : {0.25, 0.5, 0.75, 1.0}) {
      Eigen::VectorXd blend(m.num_faces());
      std::vector<double> change;
      for (Index f = 0; f < m.num_faces(); ++f) {
        blend[f] = std::pow(a_in[f], 1 - tb) * std::pow(scale_ideal * iso[f], tb);
      }
      const double s2 = a_in.sum() / blend.sum();
      for (Index f = 0; f < m.num_faces(); ++f) change.push_back(std::abs(std::log(s2 * blend[f] / a_in[f])));
      std::sort(change.begin(), change.end());
      std::printf("  blend t=%.2f rho %.3f  |log area ratio| median %.2f p90 %.2f\n", tb,
                  spearman_correlation(k, density_from_face_areas(blend)), change[change.size() / 2],
                  change[change.size() * 9 / 10]);
    }
    std::printf("%s: input rho %.3f | ideal iso faces %.3f | ideal sqrt|K| faces %.3f | rho(k, 1-ring mean k) %.3f\n",
                argv[a], redistribution_rho(k, m.V, m.F), spearman_correlation(k, density_from_face_areas(iso)),
                spearman_correlation(k, density_from_face_areas(gauss)), spearman_correlation(k, smooth));
  }
}
