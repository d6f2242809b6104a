// The input check of input_check.h: the share of poor faces and of sharp interior edges.
#include "vertexflow/input_check.h"

#include "vertexflow/quality.h"

#include "common/bucket_by_key.h"
#include "numerics/parallel.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <span>
#include <stdexcept>
#include <vector>

namespace vertexflow {
namespace {

// A face's side on the edge (a, b), a < b, kept in the bucket of a.
struct EdgeSide {
  Index b;
  Index face;
  bool operator<(const EdgeSide& o) const { return b != o.b ? b < o.b : face < o.face; }
};

}  // namespace

const char* hold_reason_name(HoldReason reason) {
  switch (reason) {
    case HoldReason::None:
      return "none";
    case HoldReason::Decimated:
      return "decimated";
    case HoldReason::ControlMesh:
      return "subdivision control mesh";
    case HoldReason::AlreadyFitted:
      return "already fitted";
  }
  return "?";
}

InputCheck check_input(const Vertices& V, const Faces& F, const InputCheckOptions& options, const Topology* topology) {
  for (const double t : {options.max_poor_face_fraction, options.max_sharp_edge_fraction})
    if (!(t >= 0 && t <= 1)) throw std::invalid_argument("input check: thresholds must be in [0, 1]");
  InputCheck check;

  // Unit normals; faces without area get none, and their edges are left out.
  const Index m = F.rows();
  const auto distinct_corners = [&F](Index f) {
    return F(f, 0) != F(f, 1) && F(f, 1) != F(f, 2) && F(f, 2) != F(f, 0);
  };
  std::vector<Eigen::Vector3d> normal(static_cast<std::size_t>(m));
  std::vector<char> has_normal(static_cast<std::size_t>(m), 0);
  parallel_for_index(m, [&](Index f) {
    const Eigen::Vector3d p = V.row(F(f, 0)).transpose(), q = V.row(F(f, 1)).transpose(),
                          r = V.row(F(f, 2)).transpose();
    const Eigen::Vector3d n = (q - p).cross(r - p);
    const double length = n.norm();
    if (length > 0 && std::isfinite(length) && distinct_corners(f)) {
      normal[static_cast<std::size_t>(f)] = n / length;
      has_normal[static_cast<std::size_t>(f)] = 1;
    }
  });
  const double cos_sharp = std::cos(kSharpEdgeAngle * std::numbers::pi / 180);
  Index sharp = 0;
  std::vector<char> on_boundary(static_cast<std::size_t>(V.rows()), 0);
  if (topology && topology->non_manifold_edges.empty() && topology->num_faces == m) {
    // The edges the caller's topology already found: at most two faces each, so an edge is
    // interior where face_adjacency names the other face (each counted from its lower face).
    for (Index e = 0; e < topology->num_edges(); ++e)
      if (topology->edge_face_count[static_cast<std::size_t>(e)] == 1)
        on_boundary[static_cast<std::size_t>(topology->edges(e, 0))] =
            on_boundary[static_cast<std::size_t>(topology->edges(e, 1))] = 1;
    using Counts = Eigen::Matrix<std::int64_t, 2, 1>;  // interior, sharp: integers, so any order
    const Counts counts =
        deterministic_sum(m, kVerticesPerChunk, Counts::Zero().eval(), [&](std::ptrdiff_t begin, std::ptrdiff_t end) {
          Counts sum = Counts::Zero();
          for (auto f = static_cast<Index>(begin); f < static_cast<Index>(end); ++f)
            for (int k = 0; k < 3; ++k) {
              const Index g = topology->face_adjacency(f, k);
              if (g <= f || !has_normal[static_cast<std::size_t>(f)] || !has_normal[static_cast<std::size_t>(g)])
                continue;
              ++sum[0];
              if (normal[static_cast<std::size_t>(f)].dot(normal[static_cast<std::size_t>(g)]) < cos_sharp) ++sum[1];
            }
          return sum;
        });
    check.interior_edges = static_cast<Index>(counts[0]);
    sharp = static_cast<Index>(counts[1]);
  } else {
    // Each edge's sides (faces with three distinct corners) in the bucket of its smaller vertex,
    // each bucket sorted so an edge's faces are adjacent, in increasing order (deterministic, no
    // hashing; a sort of all sides at once took 3% of a 10M-vertex run on one core).
    KeyBuckets<EdgeSide> sides = bucket_by_key<EdgeSide>(static_cast<std::size_t>(V.rows()), [&](auto&& emit) {
      for (Index f = 0; f < m; ++f)
        if (distinct_corners(f))
          for (int k = 0; k < 3; ++k) {
            const Index u = F(f, k), w = F(f, (k + 1) % 3);
            emit(static_cast<std::size_t>(std::min(u, w)), EdgeSide{std::max(u, w), f});
          }
    });
    parallel_for_index(static_cast<Index>(V.rows()), [&](Index a) {
      const std::span<EdgeSide> bucket = sides.of(static_cast<std::size_t>(a));
      std::sort(bucket.begin(), bucket.end());
    });
    for (Index a = 0; a < static_cast<Index>(V.rows()); ++a) {
      const std::span<EdgeSide> bucket = sides.of(static_cast<std::size_t>(a));
      for (std::size_t i = 0; i < bucket.size();) {
        std::size_t j = i + 1;
        while (j < bucket.size() && bucket[j].b == bucket[i].b) ++j;
        if (j - i == 1)
          on_boundary[static_cast<std::size_t>(a)] = on_boundary[static_cast<std::size_t>(bucket[i].b)] = 1;
        // The interior edges of the sharp share: two sides that have a normal.
        Index with_normal[2] = {0, 0};
        std::size_t count = 0;
        for (std::size_t k = i; k < j; ++k)
          if (has_normal[static_cast<std::size_t>(bucket[k].face)]) {
            if (count < 2) with_normal[count] = bucket[k].face;
            ++count;
          }
        if (count == 2) {
          ++check.interior_edges;
          const double c =
              normal[static_cast<std::size_t>(with_normal[0])].dot(normal[static_cast<std::size_t>(with_normal[1])]);
          if (c < cos_sharp) ++sharp;
        }
        i = j;
      }
    }
  }
  if (check.interior_edges > 0)
    check.sharp_edge_fraction = static_cast<double>(sharp) / static_cast<double>(check.interior_edges);

  const Eigen::VectorXd quality = triangle_quality(V, F);
  Index poor_interior = 0, poor_all = 0;
  for (Index f = 0; f < m; ++f) {
    const bool rim = on_boundary[static_cast<std::size_t>(F(f, 0))] || on_boundary[static_cast<std::size_t>(F(f, 1))] ||
                     on_boundary[static_cast<std::size_t>(F(f, 2))];
    const bool poor = quality[f] < 0.3;  // summarize_quality's fraction_below_0_3
    poor_all += poor;
    if (rim) {
      ++check.rim_faces;
    } else {
      ++check.interior_faces;
      poor_interior += poor;
    }
  }
  if (check.interior_faces > 0)
    check.poor_face_fraction = static_cast<double>(poor_interior) / static_cast<double>(check.interior_faces);
  else if (m > 0)
    check.poor_face_fraction = static_cast<double>(poor_all) / static_cast<double>(m);

  if (check.poor_face_fraction > options.max_poor_face_fraction)
    check.reason = HoldReason::Decimated;
  else if (check.sharp_edge_fraction > options.max_sharp_edge_fraction)
    check.reason = HoldReason::ControlMesh;
  return check;
}

}  // namespace vertexflow
