// Experiment (not a benchmark): what the flow's feature detection (vertexflow/features.h) marks on
// a mesh: sharp edges, creases, corners and patches at a given feature angle.
#include "vertexflow/curvature.h"
#include "vertexflow/features.h"
#include "vertexflow/io.h"
#include "vertexflow/topology.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <map>
#include <vector>

using namespace vertexflow;

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: flow_features FEATURE_ANGLE_DEGREES MESH...\n");
    return 2;
  }
  const double angle = std::atof(argv[1]);
  for (int a = 2; a < argc; ++a) {
    const Mesh m = read_mesh(argv[a]);
    const Topology t = build_topology(m.F, m.num_vertices());
    const SurfaceFeatures s = detect_features(m.V, m.F, t, angle);
    std::map<std::size_t, int> by_count;
    int crease = 0, corner = 0;
    for (std::size_t v = 0; v < s.vertex_kind.size(); ++v) {
      if (s.vertex_kind[v] == SurfaceFeatures::Kind::Crease) ++crease;
      if (s.vertex_kind[v] == SurfaceFeatures::Kind::Corner) {
        ++corner;
        ++by_count[static_cast<std::size_t>(s.sharp_count(static_cast<Index>(v)))];
      }
    }
    long sharp = 0;
    for (char c : s.sharp_edge) sharp += c;
    // dihedral angle histogram
    std::map<int, int> hist;
    for (Index f = 0; f < m.num_faces(); ++f)
      for (int k = 0; k < 3; ++k) {
        const Index g = t.face_adjacency(f, k);
        if (g < f) continue;
        const Eigen::Vector3d nf = face_normal(m.V, m.F, f).normalized(), ng = face_normal(m.V, m.F, g).normalized();
        const double deg = std::acos(std::clamp(nf.dot(ng), -1.0, 1.0)) * 180 / M_PI;
        ++hist[deg < 20 ? 0 : deg < 30 ? 20 : deg < 40 ? 30 : deg < 50 ? 40 : deg < 60 ? 50 : deg < 80 ? 60 : 80];
      }
    std::printf("%s @%g: V %ld E %ld sharp edges %ld crease v %d corner v %d (", argv[a], angle, (long)m.num_vertices(),
                (long)t.num_edges(), sharp, crease, corner);
    for (auto [c, n] : by_count) std::printf("%zu sharp:%d ", c, n);
    std::printf(") dihedral:");
    for (auto [d, n] : hist) std::printf(" >=%d:%d", d, n);
    std::printf("\n");
    // components of sharp edges: size, mean dihedral
    std::vector<Index> parent(m.num_vertices());
    for (Index v = 0; v < m.num_vertices(); ++v) parent[v] = v;
    std::function<Index(Index)> root = [&](Index v) { return parent[v] == v ? v : parent[v] = root(parent[v]); };
    std::vector<double> dihedral(t.num_edges(), 0);
    for (Index f = 0; f < m.num_faces(); ++f)
      for (int k = 0; k < 3; ++k) {
        const Index g = t.face_adjacency(f, k);
        if (g < f) continue;
        const Eigen::Vector3d nf = face_normal(m.V, m.F, f).normalized(), ng = face_normal(m.V, m.F, g).normalized();
        dihedral[t.face_edges(f, k)] = std::acos(std::clamp(nf.dot(ng), -1.0, 1.0)) * 180 / M_PI;
      }
    for (Index e = 0; e < t.num_edges(); ++e)
      if (s.sharp_edge[e]) parent[root(t.edges(e, 0))] = root(t.edges(e, 1));
    std::map<Index, std::vector<double>> comp;
    for (Index e = 0; e < t.num_edges(); ++e)
      if (s.sharp_edge[e]) comp[root(t.edges(e, 0))].push_back(dihedral[e]);
    std::map<Index, int> corners;
    for (Index v = 0; v < m.num_vertices(); ++v)
      if (s.vertex_kind[v] == SurfaceFeatures::Kind::Corner) ++corners[root(v)];
    {
      std::vector<double> ratios;
      const double th = angle;
      for (Index f = 0; f < m.num_faces(); ++f)
        for (int k = 0; k < 3; ++k) {
          const Index g = t.face_adjacency(f, k);
          if (g < f) continue;
          const Index e = t.face_edges(f, k);
          if (dihedral[e] <= th) continue;
          double around = 0;
          for (const Index h : {f, g})
            for (int j = 0; j < 3; ++j) {
              const Index o = t.face_edges(h, j);
              if (o != e && dihedral[o] <= th) around = std::max(around, dihedral[o]);
            }
          ratios.push_back(dihedral[e] / std::max(around, 1e-3));
        }
      std::sort(ratios.begin(), ratios.end());
      int above2 = 0, above3 = 0;
      for (double r : ratios) {
        above2 += r >= 2;
        above3 += r >= 3;
      }
      if (!ratios.empty())
        std::printf("  jump ratio over %zu edges: p10 %.2f p50 %.2f p90 %.2f; >=2: %d >=3: %d\n", ratios.size(),
                    ratios[ratios.size() / 10], ratios[ratios.size() / 2], ratios[ratios.size() * 9 / 10], above2,
                    above3);
    }
    std::printf("  components:");
    for (auto& [r, d] : comp) {
      double mean = 0, mx = 0;
      for (double x : d) {
        mean += x / d.size();
        mx = std::max(mx, x);
      }
      std::printf(" [%zu e, mean %.0f max %.0f, %d corners]", d.size(), mean, mx, corners[r]);
    }
    std::printf("\n");
  }
}
