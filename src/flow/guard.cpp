#include "guard.h"

#include "surface_projection.h"
#include "vertexflow/quality.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>

namespace vertexflow {
namespace {

constexpr char kFlippedOrDegenerate = 1, kLowQuality = 2;

char face_badness(const GuardCriteria& criteria, const Vertices& after, Index f) {
  const Faces& F = criteria.F;
  const Eigen::Vector3d n0 = face_normal(criteria.before, F, f), n1 = face_normal(after, F, f);
  // Written as !(>) so that a zero-area face is never judged, even where min_area is 0.
  if (!(0.5 * n0.norm() > criteria.min_area)) return 0;
  if (n0.dot(n1) <= 0 || 0.5 * n1.norm() < criteria.min_area) return kFlippedOrDegenerate;
  const Eigen::Vector3d a = after.row(F(f, 0)), b = after.row(F(f, 1)), c = after.row(F(f, 2));
  return triangle_quality(a, b, c) < criteria.quality_floor[f] ? kLowQuality : 0;
}

std::vector<char> bad_faces(const GuardCriteria& criteria, const Vertices& after) {
  std::vector<char> bad(static_cast<std::size_t>(criteria.F.rows()), 0);
  tbb::parallel_for(tbb::blocked_range<Index>(0, static_cast<Index>(criteria.F.rows()), 4096),
                    [&](const tbb::blocked_range<Index>& r) {
                      for (Index f = r.begin(); f != r.end(); ++f)
                        bad[static_cast<std::size_t>(f)] = face_badness(criteria, after, f);
                    });
  return bad;
}

}  // namespace

GuardCriteria guard_criteria(const Vertices& before, const Faces& F, double min_quality) {
  const double diagonal = bounding_box(before).diagonal();
  GuardCriteria criteria{before, F, kDegenerateAreaRelative * diagonal * diagonal, triangle_quality(before, F)};
  criteria.quality_floor = criteria.quality_floor.cwiseMin(min_quality);
  return criteria;
}

void guard(Vertices& X, const Vertices& anchor, const Vertices& input, const GuardCriteria& criteria,
           const std::vector<char>& fixed, const Topology& topology, const SurfaceFeatures& features,
           const FlowOptions& options, std::vector<char>& shortened, FlowReport& report) {
  const Faces& F = criteria.F;
  const Index n = static_cast<Index>(X.rows());
  const Vertices displacement = X - anchor;
  std::vector<double> step(static_cast<std::size_t>(n), 1.0);
  std::vector<char> bad = bad_faces(criteria, X);
  report.flipped_before_guard += static_cast<Index>(std::count(bad.begin(), bad.end(), kFlippedOrDegenerate));
  report.low_quality_before_guard += static_cast<Index>(std::count(bad.begin(), bad.end(), kLowQuality));
  // Each round halves every free vertex of a bad face once; after max_halvings rounds their
  // displacement is zero, and a face whose vertices are all back at the anchor is not bad. Only
  // the faces around the vertices a round moved are judged again. The loop ends when a round
  // changes no step: steps only ever shrink, through at most max_halvings values each, so the
  // loop is finite whatever the geometry, even if rounding left a face bad at its anchor.
  std::vector<char> touched(static_cast<std::size_t>(n), 0);
  std::vector<Index> bad_list;
  for (Index f = 0; f < F.rows(); ++f) {
    if (bad[static_cast<std::size_t>(f)]) bad_list.push_back(f);
  }
  for (int round = 1; !bad_list.empty(); ++round) {
    std::vector<Index> moved, reproject;
    for (const Index f : bad_list) {
      for (int k = 0; k < 3; ++k) {
        const Index i = F(f, k);
        const auto v = static_cast<std::size_t>(i);
        if (touched[v] || fixed[v]) continue;
        touched[v] = 1;
        moved.push_back(i);
      }
    }
    std::sort(moved.begin(), moved.end());
    bool any_step_changed = false;
    for (const Index i : moved) {
      const auto v = static_cast<std::size_t>(i);
      touched[v] = 0;
      const double new_step = round >= options.max_halvings ? 0.0 : 0.5 * step[v];
      any_step_changed = any_step_changed || new_step != step[v];
      step[v] = new_step;
      shortened[v] = 1;
      X.row(i) = anchor.row(i) + step[v] * displacement.row(i);
      // Back onto the surface, except at step 0: the anchor itself, exactly.
      if (step[v] != 0.0 && options.project_to_input) reproject.push_back(i);
    }
    project_near_vertices(X, reproject, input, F, topology, features);
    std::vector<Index> faces;
    for (const Index i : moved) {
      for (Index k = topology.face_offsets[static_cast<std::size_t>(i)];
           k < topology.face_offsets[static_cast<std::size_t>(i) + 1]; ++k)
        faces.push_back(topology.vertex_faces[static_cast<std::size_t>(k)]);
    }
    std::sort(faces.begin(), faces.end());
    faces.erase(std::unique(faces.begin(), faces.end()), faces.end());
    for (const Index f : faces) bad[static_cast<std::size_t>(f)] = face_badness(criteria, X, f);
    bad_list.clear();
    for (const Index f : faces) {
      if (bad[static_cast<std::size_t>(f)]) bad_list.push_back(f);
    }
    // Bad faces away from the moved vertices cannot exist: they were bad before and so had all
    // their free vertices moved (or all fixed, and then they are at the anchor and not bad).
    if (!any_step_changed) break;
  }
}

}  // namespace vertexflow
