#include "guard.h"

#include "numerics/parallel.h"
#include "vertexflow/quality.h"

#include <fmt/format.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <iterator>
#include <limits>
#include <stdexcept>
#include <utility>

namespace vertexflow {
namespace {

constexpr char kFlippedOrDegenerate = 1, kLowQuality = 2;
// The passes stop when one brings fewer than 1 / kPassGainStop of the vertices it retried to
// their targets, or after kGuardPasses. Measured: on the 1M-vertex armadillo the passes bring
// 20%, 5%, 1.5%, then under 0.5% each (16 passes cost 3.2 s, 3 cost 0.37 s); on the sliver
// plate of the tests 10-30% each for several passes.
constexpr std::size_t kPassGainStop = 50;
constexpr int kGuardPasses = 16;
// The bad faces of a halving round are judged on all threads from this many on (a handful, the
// usual case on small meshes, cost less on the calling thread), in tasks of kFacesPerTask. On
// the 9.7M-vertex armadillo the rounds judged tens of thousands of faces each, on one core: most
// of the guard's 6-7 s.
constexpr Index kSerialBelow = 2048, kFacesPerTask = 512;

// How good face f is with corners a, b, c: > 0 for a good face (its quality above its floor),
// <= 0 for a bad one, and lower the worse it is: in (-2, -1] for a flipped face (by how far its
// normal turned), -1 for a degenerate one, (-1, 0) for one below its quality floor. A face
// degenerate in `before` has no normal to judge against and is never bad.
double face_score(const GuardCriteria& criteria, Index f, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                  const Eigen::Vector3d& c) {
  const Eigen::Vector3d n0 = face_normal(criteria.before, criteria.F, f), n1 = (b - a).cross(c - a);
  // Written as !(>) so that a zero-area face is never judged, even where min_area is 0.
  if (!(0.5 * n0.norm() > criteria.min_area)) return std::numeric_limits<double>::infinity();
  if (n0.dot(n1) <= 0) return -1 + n0.normalized().dot(n1.normalized());
  if (0.5 * n1.norm() < criteria.min_area) return -1;
  const double margin = triangle_quality(a, b, c) - criteria.quality_floor[f];
  return margin < 0 ? margin : std::max(margin, std::numeric_limits<double>::min());
}

char face_badness(const GuardCriteria& criteria, const Vertices& X, Index f) {
  const Faces& F = criteria.F;
  const double score = face_score(criteria, f, X.row(F(f, 0)), X.row(F(f, 1)), X.row(F(f, 2)));
  return score > 0 ? 0 : score <= -1 ? kFlippedOrDegenerate : kLowQuality;
}

std::vector<char> bad_faces(const GuardCriteria& criteria, const Vertices& X) {
  std::vector<char> bad(static_cast<std::size_t>(criteria.F.rows()), 0);
  tbb::parallel_for(tbb::blocked_range<Index>(0, static_cast<Index>(criteria.F.rows()), 4096),
                    [&](const tbb::blocked_range<Index>& r) {
                      for (Index f = r.begin(); f != r.end(); ++f)
                        bad[static_cast<std::size_t>(f)] = face_badness(criteria, X, f);
                    });
  return bad;
}

// The halving state of the vertices that shorten_until_good moved: their displacement from the
// anchor at the call's start, step and halvings. Untouched vertices have step 1 and are where
// the call found them. The guard keeps one across its calls and resets the vertices each call
// touched: buffers of the mesh's size filled afresh by every call (and the copy X - anchor) made
// each call O(n), about 1 s of the 10M-vertex guard's 5-8 s on one core (docs/benchmarks.md).
class HalvingState {
 public:
  explicit HalvingState(std::size_t n) : slot_(n, -1), chosen_(n, 0) {}

  // Vertex i's displacement from `anchor` when the call started (X is unchanged where untouched).
  [[nodiscard]] Eigen::Vector3d displacement(Index i, const Vertices& X, const Vertices& anchor) const {
    const int s = slot_[static_cast<std::size_t>(i)];
    return s >= 0 ? touched_[static_cast<std::size_t>(s)].displacement : Eigen::Vector3d(X.row(i) - anchor.row(i));
  }
  [[nodiscard]] double step(Index i) const {
    const int s = slot_[static_cast<std::size_t>(i)];
    return s >= 0 ? touched_[static_cast<std::size_t>(s)].step : 1.0;
  }
  // Halves vertex i's step (0 at its max_halvings-th halving) and returns the new step and
  // displacement.
  std::pair<double, Eigen::Vector3d> halve(Index i, const Vertices& X, const Vertices& anchor, int max_halvings) {
    int& s = slot_[static_cast<std::size_t>(i)];
    if (s < 0) {
      s = static_cast<int>(touched_.size());
      touched_.push_back({i, Eigen::Vector3d(X.row(i) - anchor.row(i)), 1.0, 0});
    }
    Touched& t = touched_[static_cast<std::size_t>(s)];
    t.step = ++t.halvings >= max_halvings ? 0.0 : 0.5 * t.step;
    return {t.step, t.displacement};
  }
  // Per round: whether a vertex is already chosen.
  std::vector<char>& chosen() { return chosen_; }
  // Forgets every vertex touched since the last reset.
  void reset() {
    for (const Touched& t : touched_) slot_[static_cast<std::size_t>(t.vertex)] = -1;
    touched_.clear();
  }

 private:
  struct Touched {
    Index vertex;
    Eigen::Vector3d displacement;
    double step;
    int halvings;
  };
  std::vector<int> slot_;  // index in touched_, or -1
  std::vector<Touched> touched_;
  std::vector<char> chosen_;
};

// The free corner of bad face f whose halving helps f most (ties: the first corner), or -1 if
// every corner is fixed or already back at its anchor. Shortening only that corner, and not all
// three, keeps the moves of corners that did not cause the damage: a sliver flips when one of
// its corners crosses the opposite edge, and halving the other two as well shortened 21% of
// fandisk's vertices for its 29 low-quality faces (now 0.4%).
Index corner_to_shorten(const GuardCriteria& criteria, Index f, const Vertices& X, const Vertices& anchor,
                        const HalvingState& state, const std::vector<char>& fixed) {
  const Faces& F = criteria.F;
  Index best = -1;
  double best_score = -std::numeric_limits<double>::infinity();
  for (int k = 0; k < 3; ++k) {
    const Index i = F(f, k);
    const auto v = static_cast<std::size_t>(i);
    const double step = state.step(i);
    if (fixed[v] || step == 0.0) continue;
    Eigen::Vector3d corner[3] = {X.row(F(f, 0)), X.row(F(f, 1)), X.row(F(f, 2))};
    corner[k] = anchor.row(i).transpose() + 0.5 * step * state.displacement(i, X, anchor);
    const double score = face_score(criteria, f, corner[0], corner[1], corner[2]);
    if (best < 0 || score > best_score) {
      best = i;
      best_score = score;
    }
  }
  return best;
}

// The faces around `vertices`, sorted, each once.
std::vector<Index> faces_around(const std::vector<Index>& vertices, const Topology& topology) {
  std::vector<Index> faces;
  for (const Index i : vertices) {
    for (Index k = topology.face_offsets[static_cast<std::size_t>(i)];
         k < topology.face_offsets[static_cast<std::size_t>(i) + 1]; ++k)
      faces.push_back(topology.vertex_faces[static_cast<std::size_t>(k)]);
  }
  std::sort(faces.begin(), faces.end());
  faces.erase(std::unique(faces.begin(), faces.end()), faces.end());
  return faces;
}

// The faces of `faces` that are bad in X, in the order of `faces`: judged on all threads (each
// face on its own), collected in order.
std::vector<Index> bad_among(const std::vector<Index>& faces, const GuardCriteria& criteria, const Vertices& X) {
  std::vector<char> is_bad(faces.size());
  parallel_for_index(
      static_cast<Index>(faces.size()),
      [&](Index k) {
        is_bad[static_cast<std::size_t>(k)] = face_badness(criteria, X, faces[static_cast<std::size_t>(k)]) != 0;
      },
      kFacesPerTask, kSerialBelow);
  std::vector<Index> bad;
  for (std::size_t k = 0; k < faces.size(); ++k)
    if (is_bad[k]) bad.push_back(faces[k]);
  return bad;
}

// One pass: halves, round after round, the chosen corner (corner_to_shorten) of every bad face
// until no face is bad. A vertex is halved at most once per round and set to its anchor at its
// max_halvings-th halving, so the loop is finite whatever the geometry: it ends when a round
// finds no corner to shorten. `bad_list` (sorted) holds every bad face of X. Marks in
// `shortened` the vertices it halved.
void shorten_until_good(Vertices& X, const Vertices& anchor, const GuardCriteria& criteria, std::vector<Index> bad_list,
                        const std::vector<char>& fixed, const Topology& topology, const GuardOptions& options,
                        const Reprojection& reproject, std::vector<char>& shortened, HalvingState& state) {
  std::vector<char>& chosen = state.chosen();
  std::vector<Index> corner;
  while (!bad_list.empty()) {
    std::vector<Index> moved, to_reproject;
    // Each bad face's corner on all threads (they only read X, anchor and the state), then the
    // distinct ones: the same set, since it does not depend on the order.
    corner.resize(bad_list.size());
    parallel_for_index(
        static_cast<Index>(bad_list.size()),
        [&](Index k) {
          corner[static_cast<std::size_t>(k)] =
              corner_to_shorten(criteria, bad_list[static_cast<std::size_t>(k)], X, anchor, state, fixed);
        },
        kFacesPerTask, kSerialBelow);
    for (const Index i : corner) {
      if (i < 0 || chosen[static_cast<std::size_t>(i)]) continue;
      chosen[static_cast<std::size_t>(i)] = 1;
      moved.push_back(i);
    }
    if (moved.empty()) break;  // only faces bad at their anchors, through rounding, are left
    std::sort(moved.begin(), moved.end());
    for (const Index i : moved) {
      const auto v = static_cast<std::size_t>(i);
      chosen[v] = 0;
      const auto [step, displacement] = state.halve(i, X, anchor, options.max_halvings);
      shortened[v] = 1;
      X.row(i) = anchor.row(i) + step * displacement.transpose();
      // Back onto the surface, except at step 0: the anchor itself, exactly.
      if (step != 0.0 && reproject) to_reproject.push_back(i);
    }
    if (reproject) reproject(X, to_reproject);
    // Only the faces around the moved vertices can have changed; the other bad faces stay bad.
    const std::vector<Index> faces = faces_around(moved, topology);
    std::vector<Index> unchanged;
    std::set_difference(bad_list.begin(), bad_list.end(), faces.begin(), faces.end(), std::back_inserter(unchanged));
    const std::vector<Index> now_bad = bad_among(faces, criteria, X);
    bad_list.clear();
    std::set_union(unchanged.begin(), unchanged.end(), now_bad.begin(), now_bad.end(), std::back_inserter(bad_list));
  }
  state.reset();
}

}  // namespace

GuardCriteria guard_criteria(const Vertices& before, const Faces& F, const GuardOptions& options) {
  const double min_quality = options.min_quality, sliver_floor = options.sliver_floor;
  const double diagonal = bounding_box(before).diagonal();
  const Eigen::VectorXd quality = triangle_quality(before, F);
  // The worst input face around each vertex; a face's floor is the worst of its corners'.
  std::vector<double> worst_around(static_cast<std::size_t>(before.rows()), 1.0);
  for (Index f = 0; f < F.rows(); ++f) {
    for (int k = 0; k < 3; ++k) {
      double& worst = worst_around[static_cast<std::size_t>(F(f, k))];
      worst = std::min(worst, quality[f]);
    }
  }
  GuardCriteria criteria{before, F, degenerate_area_bound(diagonal), Eigen::VectorXd(F.rows())};
  for (Index f = 0; f < F.rows(); ++f) {
    double floor = min_quality;
    for (int k = 0; k < 3; ++k) floor = std::min(floor, worst_around[static_cast<std::size_t>(F(f, k))]);
    if (quality[f] < min_quality) floor = std::min(floor, sliver_floor * quality[f]);
    criteria.quality_floor[f] = floor;
  }
  return criteria;
}

GuardCounts guard(Vertices& X, const Vertices& anchor, const GuardCriteria& criteria, const std::vector<char>& fixed,
                  const Topology& topology, const GuardOptions& options, const Reprojection& reproject,
                  std::vector<char>& shortened) {
  std::vector<char> bad = bad_faces(criteria, X);
  GuardCounts counts;
  counts.flipped_before_guard = static_cast<Index>(std::count(bad.begin(), bad.end(), kFlippedOrDegenerate));
  counts.low_quality_before_guard = static_cast<Index>(std::count(bad.begin(), bad.end(), kLowQuality));
  if (std::none_of(bad.begin(), bad.end(), [](char b) { return b != 0; })) return counts;
  const Vertices target = X;
  const auto n = static_cast<std::size_t>(X.rows());
  std::vector<Index> bad_list;
  for (Index f = 0; f < criteria.F.rows(); ++f) {
    if (bad[static_cast<std::size_t>(f)]) bad_list.push_back(f);
  }
  std::vector<char> short_of_target(n, 0);
  HalvingState state(n);
  shorten_until_good(X, anchor, criteria, std::move(bad_list), fixed, topology, options, reproject, short_of_target,
                     state);
  // Further passes offer every vertex left short of its target its whole move again, from where
  // it is now: once its neighbours have moved, a move that flipped a sliver often no longer
  // does. Each pass starts and ends with no bad face (kPassGainStop says when they stop). Their
  // buffers are allocated once.
  Vertices retry;
  std::vector<char> shortened_again(n);
  for (int pass = 0; pass < kGuardPasses; ++pass) {
    retry = X;
    std::vector<Index> retried;
    for (std::size_t v = 0; v < n; ++v) {
      if (!short_of_target[v]) continue;
      retry.row(static_cast<Index>(v)) = target.row(static_cast<Index>(v));
      retried.push_back(static_cast<Index>(v));
    }
    std::fill(shortened_again.begin(), shortened_again.end(), 0);
    // X has no bad face: only faces around the retried vertices can be bad in `retry`.
    shorten_until_good(retry, X, criteria, bad_among(faces_around(retried, topology), criteria, retry), fixed, topology,
                       options, reproject, shortened_again, state);
    std::size_t reached = 0;
    for (const Index i : retried) {
      const auto v = static_cast<std::size_t>(i);
      if (!shortened_again[v]) {
        short_of_target[v] = 0;
        ++reached;
      }
    }
    X.swap(retry);
    if (reached * kPassGainStop < retried.size()) break;
  }
  for (std::size_t v = 0; v < n; ++v) shortened[v] = shortened[v] || short_of_target[v];
  return counts;
}

void validate_guard_options(const GuardOptions& options, const char* what) {
  if (!(options.min_quality >= 0 && options.min_quality <= 1))
    throw std::invalid_argument(std::string(what) + ": min_quality must be in [0, 1]");
  if (!(options.sliver_floor >= 0 && options.sliver_floor <= 1))
    throw std::invalid_argument(std::string(what) + ": sliver_floor must be in [0, 1]");
  if (options.max_halvings < 1) throw std::invalid_argument(std::string(what) + ": max_halvings must be at least 1");
}

void validate_vertex_constraints(const VertexConstraints& constraints, Index num_vertices, const char* what) {
  if (num_vertices < 0) return;
  for (const Index p : constraints.pinned)
    if (p < 0 || p >= num_vertices)
      throw std::invalid_argument(fmt::format("{}: pinned vertex {} is out of range [0, {})", what, p, num_vertices));
}

}  // namespace vertexflow
