// Isotropic remeshing through CGAL's Polygon_mesh_processing, and the search for the target
// edge length that gives a wanted vertex count (remesh.h).
#include "vertexflow/remesh.h"

#include "surface_mesh_conversion.h"
#include "vertexflow/progress.h"
#include "vertexflow/timing.h"
#include "vertexflow/topology.h"

#include <CGAL/Polygon_mesh_processing/remesh.h>
#include <CGAL/Polygon_mesh_processing/triangulate_hole.h>
#include <CGAL/boost/graph/Euler_operations.h>
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace vertexflow {
namespace {

namespace PMP = CGAL::Polygon_mesh_processing;
using remesh_detail::SurfaceMesh;

using VertexIndex = SurfaceMesh::Vertex_index;
using FaceIndex = SurfaceMesh::Face_index;
using HalfedgeIndex = SurfaceMesh::Halfedge_index;
using EdgeIndex = SurfaceMesh::Edge_index;

void check_options(const IsotropicRemeshOptions& options) {
  if (options.iterations < 1) throw std::invalid_argument("remesh: iterations must be at least 1");
  if (options.relaxation_steps < 0) throw std::invalid_argument("remesh: relaxation steps must not be negative");
  if (!(options.small_piece_edges >= 0) || !std::isfinite(options.small_piece_edges))
    throw std::invalid_argument("remesh: small_piece_edges must be a finite number >= 0");
  if (!(options.short_loop_edges >= 0) || !std::isfinite(options.short_loop_edges))
    throw std::invalid_argument("remesh: short_loop_edges must be a finite number >= 0");
  if (!(options.fill_hole_edges >= 0) || !std::isfinite(options.fill_hole_edges))
    throw std::invalid_argument("remesh: fill_hole_edges must be a finite number >= 0");
}

// Edges shorter than this many target lengths are collapsed after CGAL's run (issue 31: a raw
// scan's remesh had edges of 1e-8). Clean remeshes have none below about 0.3.
constexpr double kMinEdgeFraction = 1e-4;
// Faces below this many times degenerate_faces' area bound (mesh.h) are repaired after the run,
// with a margin so that a result written as text and read back keeps none.
constexpr double kCapAreaMargin = 10.0;

double length(const SurfaceMesh& mesh, HalfedgeIndex h) {
  return std::sqrt(CGAL::squared_distance(mesh.point(mesh.source(h)), mesh.point(mesh.target(h))));
}

double area(const SurfaceMesh& mesh, FaceIndex f) {
  const HalfedgeIndex h = mesh.halfedge(f);
  return std::sqrt(CGAL::squared_area(mesh.point(mesh.source(h)), mesh.point(mesh.target(h)),
                                      mesh.point(mesh.target(mesh.next(h)))));
}

// The faces of `mesh` as V/F with their own vertices, in the order given.
Mesh faces_as_mesh(const SurfaceMesh& mesh, const std::vector<FaceIndex>& faces) {
  std::vector<Index> index(mesh.num_vertices(), -1);
  std::vector<VertexIndex> order;
  Mesh out;
  out.F.resize(static_cast<Index>(faces.size()), 3);
  for (std::size_t i = 0; i < faces.size(); ++i) {
    int k = 0;
    for (const VertexIndex v : CGAL::vertices_around_face(mesh.halfedge(faces[i]), mesh)) {
      if (index[v.idx()] < 0) {
        index[v.idx()] = static_cast<Index>(order.size());
        order.push_back(v);
      }
      out.F(static_cast<Index>(i), k++) = index[v.idx()];
    }
  }
  out.V.resize(static_cast<Index>(order.size()), 3);
  for (std::size_t i = 0; i < order.size(); ++i) {
    const auto& p = mesh.point(order[i]);
    out.V.row(static_cast<Index>(i)) << p.x(), p.y(), p.z();
  }
  return out;
}

// Takes the connected pieces (through edges) whose bounding-box diagonal is below
// options.small_piece_edges target lengths out of `mesh`: CGAL can only collapse such a piece
// into one or a few faces of any shape (docs/remesh.md). Returns them as V/F when they are
// kept. When every piece is that small, the input is smaller than the edge length and is
// remeshed whole rather than left empty.
Mesh take_small_pieces(SurfaceMesh& mesh, double edge_length, const IsotropicRemeshOptions& options,
                       RemeshCleanup& cleanup) {
  if (options.small_piece_edges == 0) return {};
  std::vector<int> piece(mesh.num_faces(), -1);
  std::vector<FaceIndex> stack;
  std::vector<std::vector<FaceIndex>> pieces;
  for (const FaceIndex seed : mesh.faces()) {
    if (piece[seed.idx()] >= 0) continue;
    const int id = static_cast<int>(pieces.size());
    pieces.emplace_back();
    piece[seed.idx()] = id;
    stack.assign(1, seed);
    while (!stack.empty()) {
      const FaceIndex f = stack.back();
      stack.pop_back();
      pieces.back().push_back(f);
      for (const HalfedgeIndex h : CGAL::halfedges_around_face(mesh.halfedge(f), mesh)) {
        const FaceIndex g = mesh.face(mesh.opposite(h));
        if (g != SurfaceMesh::null_face() && piece[g.idx()] < 0) {
          piece[g.idx()] = id;
          stack.push_back(g);
        }
      }
    }
  }
  std::vector<FaceIndex> small;
  Index small_count = 0;
  for (const auto& faces : pieces) {
    Eigen::AlignedBox3d box;
    for (const FaceIndex f : faces)
      for (const VertexIndex v : CGAL::vertices_around_face(mesh.halfedge(f), mesh)) {
        const auto& p = mesh.point(v);
        box.extend(Eigen::Vector3d(p.x(), p.y(), p.z()));
      }
    if (box.diagonal().norm() < options.small_piece_edges * edge_length) {
      small.insert(small.end(), faces.begin(), faces.end());
      ++small_count;
    }
  }
  if (small.empty() || small_count == static_cast<Index>(pieces.size())) return {};
  std::sort(small.begin(), small.end());
  cleanup.small_pieces = small_count;
  cleanup.small_piece_faces = static_cast<Index>(small.size());
  cleanup.small_pieces_kept = options.small_pieces == SmallPieces::keep;
  Mesh kept;
  if (cleanup.small_pieces_kept) kept = faces_as_mesh(mesh, small);
  for (const FaceIndex f : small) CGAL::Euler::remove_face(mesh.halfedge(f), mesh);
  mesh.collect_garbage();
  return kept;
}

// Marks the vertices that keep the boundary loops shorter than options.short_loop_edges target
// lengths: CGAL would collapse such a loop into a triangle of short edges, or pinch it against
// a neighbouring loop, leaving needles and zero-area faces. About one vertex per target length
// (at least 3, at most all) is held at its input position, chosen at even arc lengths. Not all
// of them: a raw scan's rim has 8 or more input edges per target edge. Not one per half target
// length either: that gave more needles at the rims (horse raw scan: 2.6% of the rim faces
// below 0.3 against 2.2%; docs/remesh.md).
void hold_short_loops(const SurfaceMesh& mesh, double edge_length, const IsotropicRemeshOptions& options,
                      SurfaceMesh::Property_map<VertexIndex, bool>& held, RemeshCleanup& cleanup) {
  if (options.short_loop_edges == 0) return;
  std::vector<char> visited(mesh.num_halfedges(), 0);
  std::vector<HalfedgeIndex> loop;
  std::vector<double> arc;
  for (const HalfedgeIndex start : mesh.halfedges()) {
    if (!mesh.is_border(start) || visited[start.idx()]) continue;
    loop.clear();
    arc.assign(1, 0.0);
    HalfedgeIndex h = start;
    do {
      visited[h.idx()] = 1;
      loop.push_back(h);
      arc.push_back(arc.back() + length(mesh, h));
      h = mesh.next(h);
    } while (h != start);
    const double perimeter = arc.back();
    if (!(perimeter < options.short_loop_edges * edge_length)) continue;
    const std::size_t n = loop.size();
    const std::size_t wanted = std::clamp<std::size_t>(static_cast<std::size_t>(perimeter / edge_length), 3, n);
    std::size_t i = 0;
    for (std::size_t k = 0; k < wanted; ++k) {
      // The first vertex at or past arc length k P / wanted, leaving enough for the others.
      const double at = perimeter * static_cast<double>(k) / static_cast<double>(wanted);
      while (i < n && arc[i] < at) ++i;
      i = std::min(i, n - (wanted - k));
      held[mesh.source(loop[i])] = true;
      ++i;
    }
    ++cleanup.short_loops;
    cleanup.held_loop_vertices += static_cast<Index>(wanted);
  }
}

// Fills the boundary loops shorter than options.fill_hole_edges target lengths with CGAL's
// hole triangulation (no new vertex), so that CGAL remeshes over them.
void fill_small_holes(SurfaceMesh& mesh, double edge_length, const IsotropicRemeshOptions& options,
                      RemeshCleanup& cleanup) {
  if (options.fill_hole_edges == 0) return;
  std::vector<char> visited(mesh.num_halfedges(), 0);
  std::vector<HalfedgeIndex> holes;
  for (const HalfedgeIndex start : mesh.halfedges()) {
    if (!mesh.is_border(start) || visited[start.idx()]) continue;
    double perimeter = 0;
    HalfedgeIndex h = start;
    do {
      visited[h.idx()] = 1;
      perimeter += length(mesh, h);
      h = mesh.next(h);
    } while (h != start);
    if (perimeter < options.fill_hole_edges * edge_length) holes.push_back(start);
  }
  for (const HalfedgeIndex h : holes) PMP::triangulate_hole(mesh, h, CGAL::Emptyset_iterator());
  cleanup.filled_holes = static_cast<Index>(holes.size());
}

// Whether collapsing e keeps the mesh manifold: CGAL's link condition, and not an interior
// edge between two boundary vertices (that would pinch).
bool can_collapse(const SurfaceMesh& mesh, EdgeIndex e) {
  const HalfedgeIndex h = mesh.halfedge(e);
  if (!mesh.is_border(e) && mesh.is_border(mesh.source(h)) && mesh.is_border(mesh.target(h))) return false;
  return CGAL::Euler::does_satisfy_link_condition(e, mesh);
}

// Collapses e, keeping a boundary endpoint where it is (the boundary stays on the input's rim),
// otherwise the midpoint.
void collapse(SurfaceMesh& mesh, EdgeIndex e) {
  const HalfedgeIndex h = mesh.halfedge(e);
  const VertexIndex a = mesh.source(h), b = mesh.target(h);
  const auto pa = mesh.point(a), pb = mesh.point(b);
  const bool border_a = mesh.is_border(a), border_b = mesh.is_border(b);
  const auto point = border_a && !border_b ? pa : border_b && !border_a ? pb : CGAL::midpoint(pa, pb);
  const VertexIndex kept = CGAL::Euler::collapse_edge(e, mesh);
  mesh.point(kept) = point;
}

// What CGAL's collapses can leave between close rims, which the other stages refuse: edges
// shorter than kMinEdgeFraction target lengths (collapsed) and faces of (almost) zero area
// without such an edge, caps (their longest edge flipped, or the face removed when that edge is
// on the boundary; a pinch this leaves is duplicated by from_surface_mesh). Touches nothing on
// a mesh without either, so clean remeshes are unchanged.
void repair_result(SurfaceMesh& mesh, double edge_length, RemeshCleanup& cleanup) {
  const double min_edge = kMinEdgeFraction * edge_length;
  Eigen::AlignedBox3d box;
  for (const VertexIndex v : mesh.vertices()) {
    const auto& p = mesh.point(v);
    box.extend(Eigen::Vector3d(p.x(), p.y(), p.z()));
  }
  const double min_area = kCapAreaMargin * kDegenerateAreaRelative * box.diagonal().squaredNorm();
  for (int round = 0; round < 10; ++round) {
    bool changed = false;
    for (const EdgeIndex e : mesh.edges()) {
      if (mesh.is_removed(e) || !(length(mesh, mesh.halfedge(e)) < min_edge) || !can_collapse(mesh, e)) continue;
      collapse(mesh, e);
      ++cleanup.collapsed_short_edges;
      changed = true;
    }
    for (const FaceIndex f : mesh.faces()) {
      if (mesh.is_removed(f) || !(area(mesh, f) < min_area)) continue;
      HalfedgeIndex longest = mesh.halfedge(f);
      for (const HalfedgeIndex h : CGAL::halfedges_around_face(mesh.halfedge(f), mesh))
        if (length(mesh, h) > length(mesh, longest)) longest = h;
      const HalfedgeIndex opposite = mesh.opposite(longest);
      if (mesh.is_border(opposite)) {
        CGAL::Euler::remove_face(longest, mesh);
        ++cleanup.removed_cap_faces;
        changed = true;
        continue;
      }
      // A flip is possible when the two apexes are not joined already.
      const VertexIndex apex = mesh.target(mesh.next(longest)), other = mesh.target(mesh.next(opposite));
      if (apex != other && !CGAL::halfedge(apex, other, mesh).second) {
        CGAL::Euler::flip_edge(longest, mesh);
        ++cleanup.flipped_cap_edges;
        changed = true;
      }
    }
    if (!changed) break;
  }
}

// Remeshes a copy of `input`, so every attempt starts from (and projects onto) the input.
Mesh run(SurfaceMesh mesh, double edge_length, const IsotropicRemeshOptions& options, SurfaceRepairs& repairs,
         RemeshCleanup& cleanup) {
  cleanup = {};
  const Mesh kept = take_small_pieces(mesh, edge_length, options, cleanup);
  fill_small_holes(mesh, edge_length, options, cleanup);
  auto held = mesh.add_property_map<VertexIndex, bool>("v:vertexflow_held", false).first;
  hold_short_loops(mesh, edge_length, options, held, cleanup);
  const auto parameters = CGAL::parameters::number_of_iterations(static_cast<unsigned>(options.iterations))
                              .number_of_relaxation_steps(static_cast<unsigned>(options.relaxation_steps))
                              .protect_constraints(options.protect_boundary);
  if (cleanup.short_loops > 0)
    PMP::isotropic_remeshing(faces(mesh), edge_length, mesh, parameters.vertex_is_constrained_map(held));
  else
    PMP::isotropic_remeshing(faces(mesh), edge_length, mesh, parameters);
  mesh.remove_property_map(held);
  repair_result(mesh, edge_length, cleanup);
  Mesh out = remesh_detail::from_surface_mesh(mesh, &repairs);
  if (kept.num_faces() > 0) {
    // Appended after the remeshed faces, unchanged.
    const Index n = out.num_vertices(), m = out.num_faces();
    out.V.conservativeResize(n + kept.num_vertices(), 3);
    out.V.bottomRows(kept.num_vertices()) = kept.V;
    out.F.conservativeResize(m + kept.num_faces(), 3);
    out.F.bottomRows(kept.num_faces()) = kept.F.array() + n;
  }
  return out;
}

// CGAL collapses an edge only while it is shorter than 4/5 of the target and splits it once it
// is longer than 4/3, and the result's edges sit in the lower part of that band: the first run
// from the equilateral estimate gave 1.14 to 1.18 times the wanted vertices on bunny, amo,
// armadillo-43k and horse-48k down-sampled to 6000, and 1.15 to 1.21 on spot and torus
// up-sampled to 5000-8000 (mean edge about 0.93 of the target). Starting from a length
// sqrt(1.16) longer saves a run in most cases; the search corrects what remains.
constexpr double kLengthFactor = 1.077;

// The area the vertex estimates divide; zero (a mesh collapsed to a point or a line) would
// turn them into 0/0.
double surface_area(const Vertices& V, const Faces& F) {
  double area = 0;
  for (Index f = 0; f < F.rows(); ++f) area += face_area(V, F, f);
  if (!(area > 0) || !std::isfinite(area))
    throw std::invalid_argument(
        fmt::format("remesh: the mesh's surface area is {:g}; there is nothing to remesh", area));
  return area;
}

// A too short edge length would make CGAL split until memory runs out (about 200 bytes per
// vertex of Surface_mesh and remeshing state): refuse beyond 50 million estimated vertices.
constexpr double kMaxVertices = 5e7;

void check_vertex_estimate(double area, double edge_length) {
  const double estimate = 2.0 * area / (std::sqrt(3.0) * edge_length * edge_length);
  if (!(estimate <= kMaxVertices))
    throw std::invalid_argument(fmt::format(
        "remesh: the edge length {:g} would give about {:.3g} vertices (at most 50 million)", edge_length, estimate));
}

}  // namespace

Mesh remesh_isotropic(const Vertices& V, const Faces& F, double edge_length, const IsotropicRemeshOptions& options,
                      SurfaceRepairs* repairs) {
  RemeshResult result = remesh_to_edge_length(V, F, edge_length, options);
  if (repairs) *repairs = result.report.repairs;
  return std::move(result.mesh);
}

RemeshResult remesh_to_edge_length(const Vertices& V, const Faces& F, double edge_length,
                                   const IsotropicRemeshOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  if (!(edge_length > 0) || !std::isfinite(edge_length))
    throw std::invalid_argument("remesh: the target edge length must be positive");
  check_options(options);
  RemeshResult result;
  RemeshReport& r = result.report;
  SurfaceMesh mesh = remesh_detail::to_surface_mesh(V, F, "remesh", &r.repairs.input_split);
  check_vertex_estimate(surface_area(V, F), edge_length);
  result.mesh = run(std::move(mesh), edge_length, options, r.repairs, r.cleanup);
  r.seconds = seconds_since(start);
  r.attempts.push_back({edge_length, result.mesh.num_vertices(), r.seconds});
  r.edge_length = edge_length;
  r.within_tolerance = true;
  r.quality = remesh_quality(result.mesh.V, result.mesh.F);
  return result;
}

RemeshQuality remesh_quality(const Vertices& V, const Faces& F) {
  RemeshQuality q;
  const Topology topology = build_topology(F, static_cast<Index>(V.rows()));
  const Eigen::VectorXd quality = triangle_quality(V, F);
  std::vector<double> interior, rim;
  for (Index f = 0; f < F.rows(); ++f) {
    bool on_rim = false;
    for (int k = 0; k < 3; ++k) on_rim = on_rim || topology.is_boundary_vertex[static_cast<std::size_t>(F(f, k))];
    (on_rim ? rim : interior).push_back(quality(f));
  }
  const auto stats = [](const std::vector<double>& values) {
    return summarize_quality(Eigen::Map<const Eigen::VectorXd>(values.data(), static_cast<Index>(values.size())));
  };
  q.all = summarize_quality(quality);
  q.interior = stats(interior);
  q.rim = stats(rim);
  q.interior_faces = static_cast<Index>(interior.size());
  q.rim_faces = static_cast<Index>(rim.size());
  q.components = topology.num_components;
  q.boundary_loops = static_cast<Index>(topology.boundary_loops.size());
  q.non_manifold_vertices = static_cast<Index>(topology.non_manifold_vertices.size());
  q.zero_area_faces = static_cast<Index>(degenerate_faces(V, F).size());
  q.min_edge_length = topology.num_edges() > 0 ? std::numeric_limits<double>::infinity() : 0.0;
  for (Index e = 0; e < topology.num_edges(); ++e)
    q.min_edge_length = std::min(q.min_edge_length, (V.row(topology.edges(e, 0)) - V.row(topology.edges(e, 1))).norm());
  return q;
}

double edge_length_for_vertex_count(double area, Index vertices) {
  return std::sqrt(2.0 * area / (std::sqrt(3.0) * static_cast<double>(std::max<Index>(vertices, 1))));
}

RemeshResult remesh_to_vertex_count(const Vertices& V, const Faces& F, const RemeshOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  if (options.target_vertices < 3 || options.target_vertices > kMaxVertices)
    throw std::invalid_argument("remesh: the target vertex count must be in [3, 50 million]");
  if (!(options.tolerance >= 0)) throw std::invalid_argument("remesh: the tolerance must not be negative");
  if (options.max_attempts < 1) throw std::invalid_argument("remesh: max_attempts must be at least 1");
  check_options(options.isotropic);
  ManifoldSplitCounts input_split;
  const SurfaceMesh input = remesh_detail::to_surface_mesh(V, F, "remesh", &input_split);
  const double target = options.target_vertices;

  RemeshResult best;
  double best_error = std::numeric_limits<double>::infinity();
  const double area = surface_area(V, F);
  double length = kLengthFactor * edge_length_for_vertex_count(area, options.target_vertices);
  for (int attempt = 0; attempt < options.max_attempts; ++attempt) {
    check_vertex_estimate(area, length);
    // Progress (progress.h): each run a part of max_attempts (the search usually ends sooner).
    report_progress(fmt::format("remesh run {}", attempt + 1), static_cast<double>(attempt) / options.max_attempts,
                    static_cast<double>(attempt + 1) / options.max_attempts);
    const auto attempt_start = std::chrono::steady_clock::now();
    SurfaceRepairs repairs{input_split, 0, 0};
    RemeshCleanup cleanup;
    Mesh mesh = run(input, length, options.isotropic, repairs, cleanup);
    const Index count = mesh.num_vertices();
    best.report.attempts.push_back({length, count, seconds_since(attempt_start)});
    const double error = std::abs(count - target);
    if (error < best_error) {
      best_error = error;
      best.mesh = std::move(mesh);
      best.report.edge_length = length;
      best.report.repairs = repairs;
      best.report.cleanup = cleanup;
    }
    if (error <= options.tolerance * target || count == 0) break;
    // #V ~ c L^-p. Once runs on both sides of the target are known, interpolate between the
    // closest of each side in log-log space, kept inside the bracket (the count is a step
    // function of L on regular inputs, so an unguarded secant can jump back and forth).
    // Before that, step with p = 2 (fixed area), or with the secant slope of the latest two
    // runs, which also absorbs what the area formula does not model (boundary, CGAL's band).
    const auto& runs = best.report.attempts;
    const RemeshAttempt* shorter = nullptr;  // longest length that gave too many vertices
    const RemeshAttempt* longer = nullptr;   // shortest length that gave too few
    for (const RemeshAttempt& a : runs) {
      if (a.vertices > target && (!shorter || a.edge_length > shorter->edge_length)) shorter = &a;
      if (a.vertices < target && (!longer || a.edge_length < longer->edge_length)) longer = &a;
    }
    if (shorter && longer && shorter->edge_length < longer->edge_length) {
      const double t =
          (std::log(shorter->vertices) - std::log(target)) / (std::log(shorter->vertices) - std::log(longer->vertices));
      const double a = std::log(shorter->edge_length), b = std::log(longer->edge_length);
      length = std::exp(a + std::clamp(t, 0.1, 0.9) * (b - a));
      continue;
    }
    double p = 2;
    if (runs.size() >= 2) {
      const RemeshAttempt& a = runs[runs.size() - 2];
      const RemeshAttempt& b = runs.back();
      const double slope = -(std::log(double(b.vertices)) - std::log(double(a.vertices))) /
                           (std::log(b.edge_length) - std::log(a.edge_length));
      if (std::isfinite(slope)) p = std::clamp(slope, 1.0, 4.0);
    }
    length *= std::pow(count / target, 1.0 / p);
  }
  best.report.within_tolerance = best_error <= options.tolerance * target;
  best.report.quality = remesh_quality(best.mesh.V, best.mesh.F);
  best.report.seconds = seconds_since(start);
  return best;
}

}  // namespace vertexflow
