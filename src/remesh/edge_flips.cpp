// Data-dependent edge flips (edge_flips.h).
#include "vertexflow/edge_flips.h"

#include "numerics/parallel.h"
#include "vertexflow/quality.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <unordered_set>
#include <vector>

namespace vertexflow {
namespace {

using Triangle = std::array<Eigen::Vector3d, 3>;

// The centroids of the 2 x 2 subdivision, as barycentric weights of the corners.
constexpr double kPoints[4][3] = {
    {2.0 / 3, 1.0 / 6, 1.0 / 6}, {1.0 / 6, 2.0 / 3, 1.0 / 6}, {1.0 / 6, 1.0 / 6, 2.0 / 3}, {1.0 / 3, 1.0 / 3, 1.0 / 3}};

Triangle corners(const Vertices& V, Index a, Index b, Index c) {
  return {V.row(a).transpose(), V.row(b).transpose(), V.row(c).transpose()};
}

Eigen::Vector3d normal_of(const Triangle& t) {
  return (t[1] - t[0]).cross(t[2] - t[0]);
}

// E(f) of edge_flips.h.
double face_error(const Triangle& t, const DistanceQuery& target) {
  double sum = 0;
  for (const auto& w : kPoints) sum += target.closest_point(w[0] * t[0] + w[1] * t[1] + w[2] * t[2]).squared_distance;
  return 0.5 * normal_of(t).norm() * sum / 4.0;
}

std::int64_t edge_key(Index a, Index b, Index n) {
  return static_cast<std::int64_t>(std::min(a, b)) * n + std::max(a, b);
}

struct Candidate {
  Index f1 = -1, f2 = -1;  // f1 holds the edge as a -> b
  Index a = 0, b = 0, c = 0, d = 0;
  double gain = 0;
  double error1 = 0, error2 = 0;  // E of the new faces (a, d, c) and (d, b, c)
};

}  // namespace

EdgeFlipResult flip_edges_toward(const Vertices& V, const Faces& F, const DistanceQuery& target,
                                 const EdgeFlipOptions& options, const Vertices* slot_normals) {
  const Index n = V.rows(), m = F.rows();
  if (n == 0 || m == 0) throw std::invalid_argument("edge flips: the mesh is empty");
  if (F.minCoeff() < 0 || F.maxCoeff() >= n) throw std::invalid_argument("edge flips: a face index is out of range");
  if (!(options.min_quality >= 0 && options.min_quality <= 1))
    throw std::invalid_argument("edge flips: min_quality must be in [0, 1]");
  if (!(options.min_gain >= 0)) throw std::invalid_argument("edge flips: min_gain must be >= 0");
  if (options.max_passes < 1) throw std::invalid_argument("edge flips: max_passes must be at least 1");
  if (slot_normals && slot_normals->rows() != m) throw std::invalid_argument("edge flips: one slot normal per face");

  EdgeFlipResult result;
  result.F = F;
  Faces& G = result.F;
  EdgeFlipReport& report = result.report;
  double area = 0;
  for (Index f = 0; f < m; ++f) area += 0.5 * normal_of(corners(V, G(f, 0), G(f, 1), G(f, 2))).norm();
  // E of every face, computed once: a flip replaces its two faces' E by the values its
  // evaluation computed for the new faces (the same corners in the same order).
  Eigen::VectorXd error(m);
  parallel_for_index(m, [&](Index f) { error[f] = face_error(corners(V, G(f, 0), G(f, 1), G(f, 2)), target); });
  auto rms = [&] { return area > 0 ? std::sqrt(error.sum() / area) : 0.0; };
  report.rms_before = rms();

  // Fixed edges stay edges: a flip removes only the edge it flips, so checking that edge suffices.
  std::vector<std::int64_t> fixed;
  for (const auto& [a, b] : options.fixed_edges)
    if (a >= 0 && b >= 0 && a < n && b < n && a != b) fixed.push_back(edge_key(a, b, n));
  std::sort(fixed.begin(), fixed.end());
  for (int pass = 0; pass < options.max_passes; ++pass) {
    // Half-edges (a -> b of face f, corner k) sorted by undirected edge: an interior manifold
    // edge is a run of exactly two, one each way.
    struct HalfEdge {
      std::int64_t key;
      Index f;
      int k;
    };
    std::vector<HalfEdge> half(static_cast<std::size_t>(3 * m));
    std::vector<Index> faces_at(static_cast<std::size_t>(n), 0);
    for (Index f = 0; f < m; ++f)
      for (int k = 0; k < 3; ++k) {
        half[static_cast<std::size_t>(3 * f + k)] = {edge_key(G(f, k), G(f, (k + 1) % 3), n), f, k};
        ++faces_at[static_cast<std::size_t>(G(f, k))];
      }
    std::sort(half.begin(), half.end(), [](const HalfEdge& x, const HalfEdge& y) {
      return x.key != y.key ? x.key < y.key : (x.f != y.f ? x.f < y.f : x.k < y.k);
    });
    std::vector<std::int64_t> edges;
    edges.reserve(half.size());
    std::vector<char> on_boundary(static_cast<std::size_t>(n), 0);
    std::vector<Candidate> candidates;
    for (std::size_t i = 0; i < half.size();) {
      std::size_t j = i;
      while (j < half.size() && half[j].key == half[i].key) ++j;
      edges.push_back(half[i].key);
      if (j - i == 1) {
        on_boundary[static_cast<std::size_t>(G(half[i].f, half[i].k))] = 1;
        on_boundary[static_cast<std::size_t>(G(half[i].f, (half[i].k + 1) % 3))] = 1;
      }
      if (j - i == 2) {
        const HalfEdge &h1 = half[i], &h2 = half[i + 1];
        const Index a = G(h1.f, h1.k), b = G(h1.f, (h1.k + 1) % 3);
        if (G(h2.f, h2.k) == b && G(h2.f, (h2.k + 1) % 3) == a) {
          Candidate c;
          c.f1 = h1.f;
          c.f2 = h2.f;
          c.a = a;
          c.b = b;
          c.c = G(h1.f, (h1.k + 2) % 3);
          c.d = G(h2.f, (h2.k + 2) % 3);
          if (c.c != c.d && !std::binary_search(fixed.begin(), fixed.end(), half[i].key)) candidates.push_back(c);
        }
      }
      i = j;
    }
    // `edges` is sorted and unique: the edges at the start of the pass.
    auto is_edge = [&](Index x, Index y) { return std::binary_search(edges.begin(), edges.end(), edge_key(x, y, n)); };
    parallel_for_index(static_cast<Index>(candidates.size()), [&](Index i) {
      Candidate& c = candidates[static_cast<std::size_t>(i)];
      c.gain = 0;
      if (is_edge(c.c, c.d)) return;
      const Triangle old1 = corners(V, c.a, c.b, c.c), old2 = corners(V, c.b, c.a, c.d);
      const Triangle new1 = corners(V, c.a, c.d, c.c), new2 = corners(V, c.d, c.b, c.c);
      const Eigen::Vector3d n1 = normal_of(old1), n2 = normal_of(old2);
      for (int k = 0; k < 2; ++k) {
        const Eigen::Vector3d normal = normal_of(k == 0 ? new1 : new2);
        if (!(normal.dot(n1) > 0 && normal.dot(n2) > 0)) return;
        if (slot_normals && normal.dot(slot_normals->row(k == 0 ? c.f1 : c.f2).transpose()) < 0) return;
      }
      const double floor = std::min({options.min_quality, triangle_quality(old1[0], old1[1], old1[2]),
                                     triangle_quality(old2[0], old2[1], old2[2])});
      if (triangle_quality(new1[0], new1[1], new1[2]) < floor || triangle_quality(new2[0], new2[1], new2[2]) < floor)
        return;
      const double before = error[c.f1] + error[c.f2];
      // A pair on T to a millionth of its edges (rounding noise) has nothing to gain.
      const double length =
          std::max({(old1[1] - old1[0]).norm(), (old1[2] - old1[1]).norm(), (old1[0] - old1[2]).norm(),
                    (old2[2] - old2[0]).norm(), (old2[2] - old2[1]).norm()});
      const double noise = 0.5 * (n1.norm() + n2.norm()) * 1e-12 * length * length;
      c.error1 = face_error(new1, target);
      c.error2 = face_error(new2, target);
      const double after = c.error1 + c.error2;
      if (before > noise && before - after > options.min_gain * before) c.gain = before - after;
    });
    std::erase_if(candidates, [](const Candidate& c) { return !(c.gain > 0); });
    std::sort(candidates.begin(), candidates.end(),
              [](const Candidate& x, const Candidate& y) { return x.gain != y.gain ? x.gain > y.gain : x.f1 < y.f1; });
    std::vector<char> touched(static_cast<std::size_t>(m), 0);
    std::unordered_set<std::int64_t> made;
    Index flipped = 0;
    // An interior vertex keeps at least three faces, a boundary one at least one.
    auto keeps_enough = [&](Index v) {
      return faces_at[static_cast<std::size_t>(v)] > (on_boundary[static_cast<std::size_t>(v)] ? 1 : 3);
    };
    for (const Candidate& c : candidates) {
      if (touched[static_cast<std::size_t>(c.f1)] || touched[static_cast<std::size_t>(c.f2)]) continue;
      if (!keeps_enough(c.a) || !keeps_enough(c.b)) continue;
      if (!made.insert(edge_key(c.c, c.d, n)).second) continue;
      G.row(c.f1) << c.a, c.d, c.c;
      G.row(c.f2) << c.d, c.b, c.c;
      error[c.f1] = c.error1;
      error[c.f2] = c.error2;
      touched[static_cast<std::size_t>(c.f1)] = touched[static_cast<std::size_t>(c.f2)] = 1;
      --faces_at[static_cast<std::size_t>(c.a)];
      --faces_at[static_cast<std::size_t>(c.b)];
      ++faces_at[static_cast<std::size_t>(c.c)];
      ++faces_at[static_cast<std::size_t>(c.d)];
      ++flipped;
    }
    report.flips += flipped;
    report.passes = pass + 1;
    if (flipped == 0) break;
  }
  report.rms_after = rms();
  return result;
}

Index faces_turned_over(const Vertices& V0, const Faces& F0, const Vertices& V, const Faces& F) {
  if (V0.rows() != V.rows() || F0.rows() != F.rows())
    throw std::invalid_argument("faces turned over: the meshes differ in vertex or face count");
  std::vector<char> turned(static_cast<std::size_t>(F.rows()), 0);
  parallel_for_index(F.rows(), [&](Index f) {
    const Eigen::Vector3d before = normal_of(corners(V0, F0(f, 0), F0(f, 1), F0(f, 2)));
    const Eigen::Vector3d after = normal_of(corners(V, F(f, 0), F(f, 1), F(f, 2)));
    turned[static_cast<std::size_t>(f)] = before.squaredNorm() > 0 && after.squaredNorm() > 0 && before.dot(after) < 0;
  });
  return static_cast<Index>(std::count(turned.begin(), turned.end(), 1));
}

}  // namespace vertexflow
