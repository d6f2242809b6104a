// Garland-Heckbert edge collapse on index arrays (quadric_collapse.h).
//
// Written here rather than called from CGAL: CGAL's Surface_mesh_simplification builds an
// Edge_profile (both one-rings as halfedges, with property-map lookups) for every candidate it
// costs and again for every collapse, on a halfedge mesh converted from and back to arrays. On
// the 1M-vertex armadillo that took 27.7 s for the first level of `vertexflow lod` alone, whose
// six levels have a 60 s budget (issue 30). The placement and stopping rule below are CGAL's
// GarlandHeckbert_plane_policies'. The quadrics are area-weighted (Garland and Heckbert's
// weighting; CGAL's plane policies weight every face alike): a fitted lod level has faces of
// very different sizes, and simplified from such a level with unweighted quadrics the chain's
// levels measured 1.5-2 times farther from the dense mesh at 10-2% than with area weights
// (bunny -14.7% -> -20.3% against CGAL's QEM over 50-2%, amo -11.0% -> -21.0%; docs/lod.md).
// From an even mesh the two agree within a few percent (tests/remesh/test_simplify.cpp).
#include "quadric_collapse.h"

#include <Eigen/Dense>
#include <boost/heap/d_ary_heap.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

namespace vertexflow::remesh_detail {
namespace {

using Vec3 = Eigen::Vector3d;

// Q(x) = x^T A x + 2 b^T x + c: the summed squared distance of x to a set of planes.
struct Quadric {
  double a00 = 0, a01 = 0, a02 = 0, a11 = 0, a12 = 0, a22 = 0, b0 = 0, b1 = 0, b2 = 0, c = 0;

  // Adds weight * (n.x + d)^2 for the plane n.x + d = 0.
  void add_plane(const Vec3& n, double d, double weight) {
    a00 += weight * n.x() * n.x();
    a01 += weight * n.x() * n.y();
    a02 += weight * n.x() * n.z();
    a11 += weight * n.y() * n.y();
    a12 += weight * n.y() * n.z();
    a22 += weight * n.z() * n.z();
    b0 += weight * d * n.x();
    b1 += weight * d * n.y();
    b2 += weight * d * n.z();
    c += weight * d * d;
  }
  Quadric& operator+=(const Quadric& o) {
    a00 += o.a00, a01 += o.a01, a02 += o.a02, a11 += o.a11, a12 += o.a12, a22 += o.a22;
    b0 += o.b0, b1 += o.b1, b2 += o.b2, c += o.c;
    return *this;
  }
  [[nodiscard]] Eigen::Matrix3d A() const {
    Eigen::Matrix3d m;
    m << a00, a01, a02, a01, a11, a12, a02, a12, a22;
    return m;
  }
  [[nodiscard]] Vec3 b() const { return {b0, b1, b2}; }
  [[nodiscard]] double operator()(const Vec3& x) const { return x.dot(A() * x) + 2 * b().dot(x) + c; }
};

Quadric operator+(Quadric a, const Quadric& b) {
  return a += b;
}

// The minimiser of q where A is invertible; otherwise the minimiser on the segment p0 p1, or
// the better end point (CGAL's construct_optimal_point_singular). "Invertible" is relative
// here: CGAL tests the determinant against exactly zero, which rounding almost never meets on a
// flat region, and then places the vertex by a near-singular solve.
Vec3 optimal_point(const Quadric& q, const Vec3& p0, const Vec3& p1) {
  const Eigen::Matrix3d A = q.A();
  const double scale = A.cwiseAbs().maxCoeff();
  const double det = A.determinant();
  if (scale > 0 && std::abs(det) > 1e-10 * scale * scale * scale) return -(A.inverse() * q.b());
  const Vec3 d = p1 - p0;
  const double a = d.dot(A * d);
  const double b = 2 * (p0.dot(A * d) + q.b().dot(d));
  const double tiny = 1e-300;
  if (std::abs(a) <= tiny) {
    if (b < -tiny) return p1;
    if (b <= tiny) return 0.5 * (p0 + p1);
    return p0;
  }
  const double t = -b / (2 * a);
  if (t < 0 || t > 1 || a < 0) return q(p0) > q(p1) ? p1 : p0;
  return p0 + t * d;
}

struct Candidate {
  double cost;
  Index a, b;
  std::uint32_t stamp_a, stamp_b;
};

// The heap keeps the largest first: order by cost descending, then by vertex indices, so that
// ties are broken the same way on every run (and by any heap: equal keys are copies of one
// candidate, at most one of them current).
struct Costlier {
  bool operator()(const Candidate& x, const Candidate& y) const {
    if (x.cost != y.cost) return x.cost > y.cost;
    if (x.a != y.a) return x.a > y.a;
    return x.b > y.b;
  }
};
// A 4-ary heap (Boost.Heap): the candidates (3M on a 2M-face mesh, 72 MB) are far larger than the
// caches, and half the depth of a binary heap saves cache misses on each push and pop. Measured
// against std::push_heap / pop_heap, `vertexflow simplify` of docs/lod.md's smooth 1M-vertex mesh
// to 1M faces, whole process, median of 3: 9.85 -> 9.49 s, the same output bytes.
using CandidateHeap = boost::heap::d_ary_heap<Candidate, boost::heap::arity<4>, boost::heap::compare<Costlier>>;

class Collapser {
 public:
  Collapser(const Vertices& V, const Faces& F, bool keep_boundary) : keep_boundary_(keep_boundary) {
    const Index n = static_cast<Index>(V.rows());
    // mesh.h's degenerate face, in terms of the squared norm of the cross product (twice the area).
    const double least_double_area = 2 * degenerate_area_bound(n > 0 ? bounding_box(V).diagonal() : 0.0);
    least_cross_squared_ = least_double_area * least_double_area;
    const Index m = static_cast<Index>(F.rows());
    position_.resize(static_cast<std::size_t>(n));
    for (Index v = 0; v < n; ++v) position_[static_cast<std::size_t>(v)] = V.row(v).transpose();
    face_.resize(static_cast<std::size_t>(m));
    for (Index f = 0; f < m; ++f) face_[static_cast<std::size_t>(f)] = {F(f, 0), F(f, 1), F(f, 2)};
    face_alive_.assign(static_cast<std::size_t>(m), 1);
    live_faces_ = m;

    // Vertex -> faces lists, each in one stretch of pool_; a vertex's merged list is appended
    // at the end after a collapse (compact_pool() reclaims the old stretches).
    list_size_.assign(static_cast<std::size_t>(n), 0);
    for (const auto& f : face_)
      for (const Index v : f) ++list_size_[static_cast<std::size_t>(v)];
    list_start_.resize(static_cast<std::size_t>(n));
    std::size_t offset = 0;
    for (Index v = 0; v < n; ++v) {
      list_start_[static_cast<std::size_t>(v)] = offset;
      offset += static_cast<std::size_t>(list_size_[static_cast<std::size_t>(v)]);
    }
    pool_.resize(offset);
    std::vector<Index> filled(static_cast<std::size_t>(n), 0);
    for (Index f = 0; f < m; ++f)
      for (const Index v : face_[static_cast<std::size_t>(f)])
        pool_[list_start_[static_cast<std::size_t>(v)] +
              static_cast<std::size_t>(filled[static_cast<std::size_t>(v)]++)] = f;
    compact_at_ = 3 * pool_.size() + 1024;
    pool_.reserve(compact_at_ + 64);

    alive_.assign(static_cast<std::size_t>(n), 1);
    stamp_.assign(static_cast<std::size_t>(n), 0);
    waiting_head_.assign(static_cast<std::size_t>(n), -1);
    mark_.assign(static_cast<std::size_t>(n), 0);
    boundary_.assign(static_cast<std::size_t>(n), 0);
    quadric_.assign(static_cast<std::size_t>(n), Quadric{});
    init_quadrics_and_boundary();
  }

  Index run(Index target_faces) {
    // Every edge once, from the smaller end.
    std::vector<Index> ring;
    for (Index v = 0; v < static_cast<Index>(alive_.size()); ++v) {
      neighbours(v, ring);
      for (const Index w : ring)
        if (v < w) push(v, w);
    }
    drop_stale_at_ = 2 * heap_.size() + 1024;
    Index collapses = 0;
    // CGAL's stopping rule (simplify.cpp's FaceBudget): go on while a collapse cannot take the
    // count below the target.
    while (live_faces_ >= target_faces + 2 && !heap_.empty()) {
      const Candidate c = heap_.top();
      heap_.pop();
      if (!current(c)) continue;
      // Copies of one candidate (pushed again before it was popped) come out one after the
      // other, and nothing changed in between: refused once, refused all.
      if (c.a == last_refused_.a && c.b == last_refused_.b && c.stamp_a == last_refused_.stamp_a &&
          c.stamp_b == last_refused_.stamp_b)
        continue;
      if (try_collapse(c.a, c.b))
        ++collapses;
      else
        last_refused_ = c;
    }
    return collapses;
  }

  Mesh result() const {
    std::vector<Index> new_index(alive_.size(), -1);
    Index count = 0;
    for (std::size_t v = 0; v < alive_.size(); ++v)
      if (alive_[v] && list_size_[v] > 0) new_index[v] = count++;
    Mesh out;
    out.V.resize(count, 3);
    for (std::size_t v = 0; v < alive_.size(); ++v)
      if (new_index[v] >= 0) out.V.row(new_index[v]) = position_[v].transpose();
    out.F.resize(live_faces_, 3);
    Index row = 0;
    for (std::size_t f = 0; f < face_.size(); ++f) {
      if (!face_alive_[f]) continue;
      for (int k = 0; k < 3; ++k)
        out.F(row, k) = new_index[static_cast<std::size_t>(face_[f][static_cast<std::size_t>(k)])];
      ++row;
    }
    return out;
  }

 private:
  static constexpr double kDiscontinuityWeight = 100;  // CGAL's discontinuity_multiplier

  std::pair<const Index*, const Index*> faces_of(Index v) const {
    const Index* begin = pool_.data() + list_start_[static_cast<std::size_t>(v)];
    return {begin, begin + list_size_[static_cast<std::size_t>(v)]};
  }

  // The vertices sharing a face with v, without v, in the order of v's faces; they are left
  // marked with the returned tick. Marks instead of a sort: this runs for both ends of every
  // candidate.
  std::uint32_t neighbours(Index v, std::vector<Index>& out) {
    out.clear();
    const std::uint32_t tick = next_tick();
    const auto [begin, end] = faces_of(v);
    for (const Index* f = begin; f != end; ++f)
      for (const Index w : face_[static_cast<std::size_t>(*f)])
        if (w != v && mark_[static_cast<std::size_t>(w)] != tick) {
          mark_[static_cast<std::size_t>(w)] = tick;
          out.push_back(w);
        }
    return tick;
  }

  std::uint32_t next_tick() {
    if (tick_ == std::numeric_limits<std::uint32_t>::max()) {
      std::fill(mark_.begin(), mark_.end(), 0);
      tick_ = 0;
    }
    return ++tick_;
  }

  Vec3 face_normal(const std::array<Index, 3>& f) const {
    const Vec3& p0 = position_[static_cast<std::size_t>(f[0])];
    return (position_[static_cast<std::size_t>(f[1])] - p0).cross(position_[static_cast<std::size_t>(f[2])] - p0);
  }

  void init_quadrics_and_boundary() {
    // Per directed face side (a, b): faces on both sides of an edge list it both ways, so a side
    // whose reverse is in no face of a is a boundary side.
    for (std::size_t f = 0; f < face_.size(); ++f) {
      const auto& corners = face_[f];
      const Vec3 normal = face_normal(corners);
      const double length = normal.norm();
      // A zero-area face has no plane; CGAL would divide by zero here.
      if (length > 0) {
        const Vec3 unit = normal / length;
        const double d = -unit.dot(position_[static_cast<std::size_t>(corners[0])]);
        // Weighted by the face's area (see the file's head).
        for (const Index v : corners) quadric_[static_cast<std::size_t>(v)].add_plane(unit, d, length / 2);
      }
      for (int k = 0; k < 3; ++k) {
        const Index a = corners[static_cast<std::size_t>(k)];
        const Index b = corners[static_cast<std::size_t>((k + 1) % 3)];
        if (!is_boundary_side(a, b)) continue;
        boundary_[static_cast<std::size_t>(a)] = boundary_[static_cast<std::size_t>(b)] = 1;
        // The plane through the edge, perpendicular to the face.
        const Vec3 edge = position_[static_cast<std::size_t>(b)] - position_[static_cast<std::size_t>(a)];
        Vec3 across = edge.cross(normal);
        const double across_length = across.norm();
        if (across_length > 0) across /= across_length;
        const double d = -across.dot(position_[static_cast<std::size_t>(b)]);
        // CGAL's weight, in the faces' units: an area.
        const double weight = kDiscontinuityWeight * edge.squaredNorm();
        quadric_[static_cast<std::size_t>(a)].add_plane(across, d, weight);
        quadric_[static_cast<std::size_t>(b)].add_plane(across, d, weight);
      }
    }
  }

  // Whether no face of a has the side b -> a (the reverse of a face's side a -> b).
  bool is_boundary_side(Index a, Index b) const {
    const auto [begin, end] = faces_of(a);
    for (const Index* f = begin; f != end; ++f) {
      const auto& c = face_[static_cast<std::size_t>(*f)];
      for (int k = 0; k < 3; ++k)
        if (c[static_cast<std::size_t>(k)] == b && c[static_cast<std::size_t>((k + 1) % 3)] == a) return false;
    }
    return true;
  }

  bool current(const Candidate& c) const {
    return alive_[static_cast<std::size_t>(c.a)] && alive_[static_cast<std::size_t>(c.b)] &&
           stamp_[static_cast<std::size_t>(c.a)] == c.stamp_a && stamp_[static_cast<std::size_t>(c.b)] == c.stamp_b;
  }

  // Where the collapse of a b puts the merged vertex: on the boundary vertex when the boundary is
  // kept and one end is on it (CGAL's Constrained_placement), else at the quadric's optimum.
  Vec3 placement(Index a, Index b) const {
    const auto ua = static_cast<std::size_t>(a), ub = static_cast<std::size_t>(b);
    if (keep_boundary_ && boundary_[ua] != boundary_[ub]) return boundary_[ua] ? position_[ua] : position_[ub];
    return optimal_point(quadric_[ua] + quadric_[ub], position_[ua], position_[ub]);
  }

  void push(Index a, Index b) {
    const auto ua = static_cast<std::size_t>(a), ub = static_cast<std::size_t>(b);
    // Two kept boundary vertices never merge (see try_collapse).
    if (keep_boundary_ && boundary_[ua] && boundary_[ub]) return;
    const Vec3 p = placement(a, b);
    const double cost = std::max(0.0, (quadric_[ua] + quadric_[ub])(p));
    heap_.push({cost, a, b, stamp_[ua], stamp_[ub]});
  }

  bool try_collapse(Index a, Index b) {
    const auto ua = static_cast<std::size_t>(a), ub = static_cast<std::size_t>(b);
    // The faces on the edge, and the vertices opposite it.
    shared_.clear();
    opposite_.clear();
    {
      const auto [begin, end] = faces_of(a);
      for (const Index* f = begin; f != end; ++f) {
        const auto& c = face_[static_cast<std::size_t>(*f)];
        if (c[0] != b && c[1] != b && c[2] != b) continue;
        shared_.push_back(*f);
        for (const Index w : c)
          if (w != a && w != b) opposite_.push_back(w);
      }
    }
    if (shared_.empty()) return false;  // a and b are no longer adjacent
    const bool boundary_edge = shared_.size() == 1;
    const bool both_on_boundary = boundary_[ua] && boundary_[ub];
    if (keep_boundary_ && both_on_boundary) return reject(a, b);
    // An interior edge between two boundary vertices would pinch the surface there.
    if (both_on_boundary && !boundary_edge) return reject(a, b);

    // Link condition: a and b share no neighbour but the vertices opposite the edge.
    const std::uint32_t around_a = neighbours(a, ring_a_);
    const std::uint32_t counted = next_tick();
    std::size_t common = 0;
    {
      const auto [begin, end] = faces_of(b);
      for (const Index* f = begin; f != end; ++f)
        for (const Index w : face_[static_cast<std::size_t>(*f)])
          if (w != a && w != b && mark_[static_cast<std::size_t>(w)] == around_a) {
            mark_[static_cast<std::size_t>(w)] = counted;
            ++common;
          }
    }
    if (common != opposite_.size()) return reject(a, b);

    // No vertex is left with too few faces: three inside (fewer folds the surface onto itself),
    // one on a boundary; a component is never collapsed away.
    const Index merged_faces = list_size_[ua] + list_size_[ub] - 2 * static_cast<Index>(shared_.size());
    const bool merged_on_boundary = boundary_[ua] || boundary_[ub];
    if (merged_faces < (merged_on_boundary ? 1 : 3)) return reject(a, b);
    for (const Index w : opposite_)
      if (list_size_[static_cast<std::size_t>(w)] - 1 < (boundary_[static_cast<std::size_t>(w)] ? 1 : 3))
        return reject(a, b);

    // Geometry: no face around the edge turns over or loses (almost) all its area.
    const Vec3 p = placement(a, b);
    for (const Index v : {a, b}) {
      const auto [begin, end] = faces_of(v);
      for (const Index* f = begin; f != end; ++f) {
        if (std::find(shared_.begin(), shared_.end(), *f) != shared_.end()) continue;
        const auto& c = face_[static_cast<std::size_t>(*f)];
        const Vec3 before = face_normal(c);
        std::array<Vec3, 3> moved;
        for (int k = 0; k < 3; ++k) {
          const Index w = c[static_cast<std::size_t>(k)];
          moved[static_cast<std::size_t>(k)] = (w == a || w == b) ? p : position_[static_cast<std::size_t>(w)];
        }
        const Vec3 after = (moved[1] - moved[0]).cross(moved[2] - moved[0]);
        const double after_squared = after.squaredNorm();
        if (!(after_squared > 0)) return reject(a, b);
        const double before_squared = before.squaredNorm();
        if (before_squared > 0 && (after.dot(before) <= 0 || after_squared < 1e-16 * before_squared))
          return reject(a, b);
        // Nor does a face become degenerate as mesh.h (and so read_mesh, which removes such
        // faces) counts it: in a flat subdivision whole rows of vertices lie on one line, and
        // collapses along them left faces down to 1.3e-17 of the diagonal squared (84 of them at
        // lod's first level of make_large_mesh's armadillo), which the relative test above let by.
        if (after_squared < least_cross_squared_ && before_squared >= least_cross_squared_) return reject(a, b);
      }
    }

    // The survivor: the boundary vertex where the boundary is kept, else the smaller index.
    const bool keep_a = keep_boundary_ ? (boundary_[ua] || (!boundary_[ub] && a < b)) : a < b;
    const Index keep = keep_a ? a : b;
    const Index gone = keep_a ? b : a;
    collapse(keep, gone, p, merged_on_boundary);
    return true;
  }

  // A refused edge waits at both ends until a collapse changes a face around either (it may be
  // valid then); only the refused edges are costed again, not every edge near the change. One
  // record per refusal, listed at both ends and released once: released twice, an edge refused
  // again would be listed twice at the end that had not released it, and so on, doubling.
  bool reject(Index a, Index b) {
    refusals_.push_back({a, b, false});
    const Index record = static_cast<Index>(refusals_.size() - 1);
    for (const Index v : {a, b}) {
      const auto uv = static_cast<std::size_t>(v);
      waiting_.push_back({record, waiting_head_[uv]});
      waiting_head_[uv] = static_cast<Index>(waiting_.size() - 1);
    }
    return false;
  }

  void release_waiting(Index v) {
    const auto uv = static_cast<std::size_t>(v);
    for (Index node = waiting_head_[uv]; node >= 0; node = waiting_[static_cast<std::size_t>(node)].next) {
      Refusal& r = refusals_[static_cast<std::size_t>(waiting_[static_cast<std::size_t>(node)].refusal)];
      if (r.released) continue;
      r.released = true;
      if (alive_[static_cast<std::size_t>(r.a)] && alive_[static_cast<std::size_t>(r.b)]) push(r.a, r.b);
    }
    waiting_head_[uv] = -1;
    // The records and nodes stay (the other end's list may still reach them): 28 bytes per
    // refusal, about 31 MB for the 1.1M refusals of the first level of a 1M-vertex mesh.
  }

  void collapse(Index keep, Index gone, const Vec3& p, bool on_boundary) {
    const auto uk = static_cast<std::size_t>(keep), ug = static_cast<std::size_t>(gone);
    for (const Index f : shared_) {
      face_alive_[static_cast<std::size_t>(f)] = 0;
      --live_faces_;
    }
    for (const Index w : opposite_) remove_from_list(w);

    // The merged list, appended to the pool.
    for (const Index v : {keep, gone}) {
      const auto [begin, end] = faces_of(v);
      for (const Index* f = begin; f != end; ++f) {
        if (!face_alive_[static_cast<std::size_t>(*f)]) continue;
        if (v == gone)
          for (Index& corner : face_[static_cast<std::size_t>(*f)])
            if (corner == gone) corner = keep;
        merged_.push_back(*f);
      }
    }
    list_start_[uk] = pool_.size();
    list_size_[uk] = static_cast<Index>(merged_.size());
    list_size_[ug] = 0;
    pool_.insert(pool_.end(), merged_.begin(), merged_.end());
    merged_.clear();

    position_[uk] = p;
    quadric_[uk] += quadric_[ug];
    boundary_[uk] = on_boundary ? 1 : 0;
    alive_[ug] = 0;
    ++stamp_[uk];

    // The edges at the merged vertex have new costs; refused edges near it may be valid now.
    neighbours(keep, ring_a_);
    for (const Index w : ring_a_) {
      push(keep, w);
      release_waiting(w);
    }
    release_waiting(keep);
    release_waiting(gone);
    if (pool_.size() > compact_at_) compact_pool();
    if (heap_.size() > drop_stale_at_) drop_stale();
  }

  // Rebuilds the heap without its outdated entries, which pile up (every collapse adds the
  // merged vertex's edges again).
  void drop_stale() {
    CandidateHeap current_only;
    current_only.reserve(heap_.size() / 2);
    for (const Candidate& c : heap_)  // in no particular order: the heap orders them again
      if (current(c)) current_only.push(c);
    heap_.swap(current_only);
    drop_stale_at_ = std::max<std::size_t>(2 * heap_.size(), 1024);
  }

  // Drops the faces that just died from w's list (w is opposite a collapsed edge).
  void remove_from_list(Index w) {
    const auto uw = static_cast<std::size_t>(w);
    Index* begin = pool_.data() + list_start_[uw];
    Index* end = begin + list_size_[uw];
    Index* kept = std::remove_if(begin, end, [&](Index f) { return !face_alive_[static_cast<std::size_t>(f)]; });
    list_size_[uw] = static_cast<Index>(kept - begin);
  }

  void compact_pool() {
    std::vector<Index> pool;
    pool.reserve(pool_.size() / 2);
    for (std::size_t v = 0; v < list_start_.size(); ++v) {
      const std::size_t start = pool.size();
      pool.insert(
          pool.end(), pool_.begin() + static_cast<std::ptrdiff_t>(list_start_[v]),
          pool_.begin() + static_cast<std::ptrdiff_t>(list_start_[v] + static_cast<std::size_t>(list_size_[v])));
      list_start_[v] = start;
    }
    pool_ = std::move(pool);
    compact_at_ = 3 * pool_.size() + 1024;
  }

  bool keep_boundary_;
  double least_cross_squared_ = 0;  // a face's squared cross product below this is degenerate
  std::vector<Vec3> position_;
  std::vector<Quadric> quadric_;
  std::vector<std::array<Index, 3>> face_;
  std::vector<char> face_alive_;
  Index live_faces_ = 0;
  std::vector<std::size_t> list_start_;
  std::vector<Index> list_size_;
  std::vector<Index> pool_;
  std::size_t compact_at_ = 0;
  std::vector<char> alive_, boundary_;
  struct Refusal {
    Index a, b;
    bool released;
  };
  struct Waiting {
    Index refusal, next;
  };
  std::vector<Refusal> refusals_;
  std::vector<Waiting> waiting_;
  std::vector<Index> waiting_head_;
  std::size_t drop_stale_at_ = 0;
  std::vector<std::uint32_t> stamp_;
  CandidateHeap heap_;
  Candidate last_refused_{0, -1, -1, 0, 0};
  // Scratch, reused by every candidate.
  std::vector<Index> shared_, opposite_, ring_a_, merged_;
  std::vector<std::uint32_t> mark_;
  std::uint32_t tick_ = 0;
};

}  // namespace

QuadricCollapseResult quadric_collapse(const Vertices& V, const Faces& F, Index target_faces, bool keep_boundary) {
  Collapser collapser(V, F, keep_boundary);
  QuadricCollapseResult out;
  out.collapses = collapser.run(target_faces);
  out.mesh = collapser.result();
  return out;
}

}  // namespace vertexflow::remesh_detail
