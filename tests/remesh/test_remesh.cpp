// Isotropic remeshing: the vertex count search, vertices on the input surface (CGAL AABB tree),
// triangle quality, topology, boundaries resampled along the input's boundary.
#include "raw_scan.h"
#include "shapes.h"
#include "test_support.h"

#include "vertexflow/distance.h"
#include "vertexflow/enhance.h"
#include "vertexflow/flow.h"
#include "vertexflow/input_check.h"
#include "vertexflow/io.h"
#include "vertexflow/quality.h"
#include "vertexflow/remesh.h"
#include "vertexflow/topology.h"

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Simple_cartesian.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <iostream>
#include <limits>
#include <set>

namespace vertexflow {
namespace {

// Largest distance from a vertex of `points` to the triangles of `surface`. The AABB tree is an
// exact closest-point query, independent of the remesher's own projection code.
double max_distance_to_surface(const Vertices& points, const Mesh& surface) {
  using K = CGAL::Simple_cartesian<double>;
  using Triangles = std::vector<K::Triangle_3>;
  using Tree = CGAL::AABB_tree<CGAL::AABB_traits<K, CGAL::AABB_triangle_primitive<K, Triangles::const_iterator>>>;
  const auto point = [&](const Vertices& V, Index i) { return K::Point_3(V(i, 0), V(i, 1), V(i, 2)); };
  Triangles triangles;
  for (Index f = 0; f < surface.num_faces(); ++f)
    triangles.emplace_back(point(surface.V, surface.F(f, 0)), point(surface.V, surface.F(f, 1)),
                           point(surface.V, surface.F(f, 2)));
  Tree tree(triangles.begin(), triangles.end());
  tree.accelerate_distance_queries();
  double worst = 0;
  for (Index v = 0; v < points.rows(); ++v) worst = std::max(worst, std::sqrt(tree.squared_distance(point(points, v))));
  return worst;
}

// Distance from p to the segment a-b.
double segment_distance(const Eigen::RowVector3d& p, const Eigen::RowVector3d& a, const Eigen::RowVector3d& b) {
  const Eigen::RowVector3d ab = b - a;
  const double t = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
  return (p - (a + t * ab)).norm();
}

TEST(Remesh, EdgeLengthForVertexCountCoversTheArea) {
  // N vertices of a closed mesh give ~2N equilateral triangles of side L: 2N (sqrt3/4) L^2 = A.
  for (const double area : {1.0, 12.566, 3e4}) {
    for (const Index n : {100, 6000}) {
      const double L = edge_length_for_vertex_count(area, n);
      EXPECT_NEAR(2.0 * n * std::sqrt(3.0) / 4.0 * L * L, area, 1e-12 * area);
    }
  }
}

TEST(Remesh, BunnyLandsWithinTheToleranceOnTheSurface) {
  const Mesh bunny = read_mesh(test::data_path("bunny.off"));
  RemeshOptions options;
  options.target_vertices = 6000;
  const RemeshResult result = remesh_to_vertex_count(bunny.V, bunny.F, options);
  const Index n = result.mesh.num_vertices();
  EXPECT_TRUE(result.report.within_tolerance);
  EXPECT_LE(std::abs(n - 6000), 300) << n;
  ASSERT_FALSE(result.report.attempts.empty());
  EXPECT_EQ(result.report.attempts.back().vertices, n);
  EXPECT_EQ(result.report.attempts.back().edge_length, result.report.edge_length);
  const double diagonal = bounding_box(bunny.V).diagonal();
  EXPECT_LT(max_distance_to_surface(result.mesh.V, bunny), 1e-9 * diagonal);
  const QualityStats quality = summarize_quality(triangle_quality(result.mesh.V, result.mesh.F));
  std::cout << "bunny -> " << n << " vertices in " << result.report.attempts.size() << " runs; quality min "
            << quality.min << " p5 " << quality.p5 << " mean " << quality.mean << " below 0.3 "
            << quality.fraction_below_0_3 << "\n";
  // Measured with CGAL 5.5.1: min 0.646, p5 0.927, mean 0.977, none below 0.3.
  EXPECT_GT(quality.mean, 0.95);
  EXPECT_GT(quality.p5, 0.85);
  EXPECT_EQ(quality.fraction_below_0_3, 0.0);
  EXPECT_GT(quality.min, 0.4);
  test::expect_same_topology(bunny, result.mesh);
}

TEST(Remesh, KeepsGenusAndComponents) {
  for (const auto& [name, target] : {std::pair<const char*, Index>{"fertility.off", 2000}, {"torus.obj", 1000}}) {
    SCOPED_TRACE(name);
    const Mesh mesh = read_mesh(test::data_path(name));
    RemeshOptions options;
    options.target_vertices = target;
    const RemeshResult result = remesh_to_vertex_count(mesh.V, mesh.F, options);
    EXPECT_TRUE(result.report.within_tolerance) << result.mesh.num_vertices();
    test::expect_same_topology(mesh, result.mesh);
    EXPECT_LT(max_distance_to_surface(result.mesh.V, mesh), 1e-9 * bounding_box(mesh.V).diagonal());
  }
}

TEST(Remesh, SearchCorrectsTheEdgeLengthAndKeepsTheClosestRun) {
  const Mesh fertility = read_mesh(test::data_path("fertility.off"));
  RemeshOptions options;
  options.target_vertices = 2000;
  options.tolerance = 0.005;  // tighter than the first estimate: the secant steps must do it
  const RemeshResult tight = remesh_to_vertex_count(fertility.V, fertility.F, options);
  std::cout << "fertility -> 2000 +- 0.5 %:";
  for (const RemeshAttempt& a : tight.report.attempts) std::cout << " " << a.vertices;
  std::cout << "\n";
  EXPECT_TRUE(tight.report.within_tolerance);
  EXPECT_LE(std::abs(tight.mesh.num_vertices() - 2000), 10);

  // An unreachable tolerance: every run is made and the closest one is returned.
  options.tolerance = 0;
  options.max_attempts = 3;
  const RemeshResult best = remesh_to_vertex_count(fertility.V, fertility.F, options);
  ASSERT_EQ(best.report.attempts.size(), 3u);
  Index closest = best.report.attempts.front().vertices;
  for (const RemeshAttempt& a : best.report.attempts)
    if (std::abs(a.vertices - 2000) < std::abs(closest - 2000)) closest = a.vertices;
  EXPECT_EQ(best.mesh.num_vertices(), closest);
  EXPECT_EQ(best.report.within_tolerance, closest == 2000);

  // Up-sampling: a target above the input's count.
  const Mesh spot = read_mesh(test::data_path("spot.obj"));
  options = {};
  options.target_vertices = 8000;
  const RemeshResult up = remesh_to_vertex_count(spot.V, spot.F, options);
  EXPECT_TRUE(up.report.within_tolerance) << up.mesh.num_vertices();
  test::expect_same_topology(spot, up.mesh);
}

TEST(Remesh, BoundaryIsResampledAlongTheInputBoundary) {
  const Mesh hemisphere = read_mesh(test::data_path("hemisphere.off"));
  const Topology input = build_topology(hemisphere.F, hemisphere.num_vertices());
  const std::vector<Index>& loop = input.boundary_loops.front();
  RemeshOptions options;
  options.target_vertices = 500;
  const RemeshResult result = remesh_to_vertex_count(hemisphere.V, hemisphere.F, options);
  EXPECT_TRUE(result.report.within_tolerance) << result.mesh.num_vertices();
  test::expect_same_topology(hemisphere, result.mesh);
  const Topology output = build_topology(result.mesh.F, result.mesh.num_vertices());
  const double diagonal = bounding_box(hemisphere.V).diagonal();
  double worst = 0;
  for (const Index v : output.boundary_loops.front()) {
    double nearest = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < loop.size(); ++i)
      nearest = std::min(nearest, segment_distance(result.mesh.V.row(v), hemisphere.V.row(loop[i]),
                                                   hemisphere.V.row(loop[(i + 1) % loop.size()])));
    worst = std::max(worst, nearest);
  }
  EXPECT_LT(worst, 1e-12 * diagonal);
  // Resampled with the interior's edge length, not kept at the input's finer spacing.
  double perimeter = 0;
  for (std::size_t i = 0; i < loop.size(); ++i)
    perimeter += (hemisphere.V.row(loop[i]) - hemisphere.V.row(loop[(i + 1) % loop.size()])).norm();
  const double spacing = perimeter / static_cast<double>(output.boundary_loops.front().size());
  EXPECT_GT(spacing, 0.7 * result.report.edge_length);
  EXPECT_LT(spacing, 1.4 * result.report.edge_length);
  EXPECT_LT(max_distance_to_surface(result.mesh.V, hemisphere), 1e-9 * diagonal);
}

TEST(Remesh, ProtectedBoundaryKeepsTheInputBoundaryEdges) {
  const Mesh hemisphere = read_mesh(test::data_path("hemisphere.off"));
  const Topology input = build_topology(hemisphere.F, hemisphere.num_vertices());
  const double spacing = mean_edge_length(hemisphere.V, input);
  IsotropicRemeshOptions options;
  options.protect_boundary = true;
  // Near the input's own spacing, where CGAL's protection gives a valid result.
  const Mesh result = remesh_isotropic(hemisphere.V, hemisphere.F, 1.2 * spacing, options);
  const Topology output = build_topology(result.F, result.num_vertices());
  ASSERT_EQ(output.boundary_loops.size(), 1u);
  ASSERT_EQ(output.boundary_loops.front().size(), input.boundary_loops.front().size());
  std::set<std::array<double, 3>> before, after;
  for (const Index v : input.boundary_loops.front())
    before.insert({hemisphere.V(v, 0), hemisphere.V(v, 1), hemisphere.V(v, 2)});
  for (const Index v : output.boundary_loops.front()) after.insert({result.V(v, 0), result.V(v, 1), result.V(v, 2)});
  EXPECT_EQ(after, before);
}

TEST(Remesh, FixedEdgeLengthGivesEdgesNearIt) {
  const Mesh sphere = test::icosphere(1.0, 5);  // fine input, 10k vertices
  const double L = 0.1;
  const Mesh result = remesh_isotropic(sphere.V, sphere.F, L);
  const Topology topology = build_topology(result.F, result.num_vertices());
  const double mean = mean_edge_length(result.V, topology);
  EXPECT_GT(mean, 0.8 * L);
  EXPECT_LT(mean, 1.2 * L);
  // Projected onto the input polyhedron: no point of it is outside the unit sphere, and no point
  // of a face is closer to the centre than the face's plane, sqrt(1 - rho^2) for circumradius rho.
  double inner = 1.0;
  for (Index f = 0; f < sphere.num_faces(); ++f) {
    const Eigen::RowVector3d a = sphere.V.row(sphere.F(f, 0)), b = sphere.V.row(sphere.F(f, 1)),
                             c = sphere.V.row(sphere.F(f, 2));
    const double rho = (a - b).norm() * (b - c).norm() * (c - a).norm() / (4 * face_area(sphere.V, sphere.F, f));
    inner = std::min(inner, std::sqrt(1 - rho * rho));
  }
  const Eigen::VectorXd radius = result.V.rowwise().norm();
  EXPECT_LT(radius.maxCoeff(), 1.0 + 1e-12);
  EXPECT_GT(radius.minCoeff(), inner - 1e-12);
  test::expect_same_topology(sphere, result);
}

// Issue 15: a scan with many holes, some touching at a vertex (non-manifold), remeshed to 6000
// vertices. The input goes through its manifold split; CGAL's collapses between close holes
// leave zero-area faces and pinched vertices, which are repaired; the result is clean and the
// flow takes it with refuse_non_manifold.
TEST(Remesh, ScanWithManyHolesGivesACleanMeshTheFlowTakes) {
  const Mesh scan = test::with_random_faces_removed(read_mesh(test::data_path("bunny.off")), 2000, 5);
  const Topology topology = build_topology(scan.F, scan.num_vertices());
  ASSERT_GE(topology.boundary_loops.size(), 100u);
  ASSERT_FALSE(topology.is_manifold());
  RemeshOptions options;
  options.target_vertices = 6000;
  const RemeshResult result = remesh_to_vertex_count(scan.V, scan.F, options);
  const SurfaceRepairs& repairs = result.report.repairs;
  std::cout << "[measured] bunny.off minus 2000 faces (" << topology.boundary_loops.size() << " loops) -> "
            << result.mesh.num_vertices() << " vertices; split " << repairs.input_split.held_vertices
            << ", removed degenerate " << repairs.removed_degenerate_faces << ", duplicated "
            << repairs.duplicated_vertices << "\n";
  test::expect_clean_surface(result.mesh);
  EXPECT_TRUE(result.report.within_tolerance);
  // Every non-manifold vertex of the input was split, and the repairs had work (measured 68 and
  // 43 with the Python sampling of the same experiment): without them the result is unclean.
  Index non_manifold_vertices = 0;
  for (const auto m : topology.is_manifold_vertex) non_manifold_vertices += m ? 0 : 1;
  EXPECT_EQ(repairs.input_split.held_vertices, non_manifold_vertices);
  EXPECT_GT(repairs.removed_degenerate_faces + repairs.duplicated_vertices, 0);
  FlowOptions strict;
  strict.refuse_non_manifold = true;
  const FlowResult flowed = vertex_flow(result.mesh.V, result.mesh.F, strict);
  EXPECT_TRUE(flipped_faces(result.mesh.V, flowed.V, result.mesh.F).empty());
  EXPECT_TRUE(degenerate_faces(flowed.V, result.mesh.F).empty());
  // Measured 0.029 mean edge lengths: the boundary vertices of about 1900 loops are fixed.
  EXPECT_GT((flowed.V - result.mesh.V).rowwise().norm().mean(), 0.012 * flowed.report.mean_edge_length);
}

// Issue 31: the raw-scan input (raw_scan.h) of bunny.off: 320 holes, 120 floating pieces (most
// smaller than the target edge), slivers on half the holes' rims.
const test::RawScan& raw_bunny() {
  static const test::RawScan scan = test::make_raw_scan(read_mesh(test::data_path("bunny.off")));
  return scan;
}

// The remesh of the raw scan to 6000 vertices, with the defaults and with the issue 31 handling
// switched off (every piece remeshed, every loop resampled), as before.
const RemeshResult& raw_bunny_remesh(bool handled) {
  static const auto run = [](bool on) {
    RemeshOptions options;
    options.target_vertices = 6000;
    if (!on) {
      options.isotropic.small_piece_edges = 0;
      options.isotropic.short_loop_edges = 0;
    }
    return remesh_to_vertex_count(raw_bunny().mesh.V, raw_bunny().mesh.F, options);
  };
  static const RemeshResult with = run(true), without = run(false);
  return handled ? with : without;
}

TEST(RemeshRawScan, TheInputHasTheIssuesProperties) {
  const test::RawScan& scan = raw_bunny();
  const Topology topology = build_topology(scan.mesh.F, scan.mesh.num_vertices());
  std::cout << "[measured] raw bunny: " << topology.num_components << " components, " << topology.boundary_loops.size()
            << " loops, " << topology.non_manifold_vertices.size() << " non-manifold vertices, " << scan.slivers
            << " slivers, " << scan.pieces_below_target << " pieces below one target edge\n";
  EXPECT_EQ(scan.holes, 320);
  EXPECT_EQ(scan.pieces, 120);
  EXPECT_GE(scan.pieces_below_target, 50);          // measured 91
  EXPECT_GE(scan.slivers, 500);                     // measured 1419
  EXPECT_GE(topology.num_components, 100);          // measured 122 (holes cut some islands off)
  EXPECT_GE(topology.boundary_loops.size(), 300u);  // measured 355 (holes merge)
  EXPECT_FALSE(topology.is_manifold());             // holes touching at a vertex: measured 37
}

// Pieces too small to remesh are removed, and counted; without that CGAL turns each into one
// face or a few of any shape.
TEST(RemeshRawScan, SmallPiecesAreRemovedAndCounted) {
  const RemeshResult& with = raw_bunny_remesh(true);
  const RemeshResult& without = raw_bunny_remesh(false);
  const RemeshCleanup& c = with.report.cleanup;
  std::cout << "[measured] raw bunny -> " << with.mesh.num_vertices() << " vertices: " << c.small_pieces
            << " small pieces (" << c.small_piece_faces << " faces), " << c.short_loops << " short loops ("
            << c.held_loop_vertices << " held), collapsed " << c.collapsed_short_edges << ", flipped "
            << c.flipped_cap_edges << ", removed " << c.removed_cap_faces << "; components "
            << with.report.quality.components << " (without: " << without.report.quality.components << ")\n";
  EXPECT_GE(c.small_pieces, 80);  // measured 105
  EXPECT_FALSE(c.small_pieces_kept);
  EXPECT_EQ(without.report.cleanup.small_pieces, 0);
  // Every remaining piece is at least small_piece_edges target edges across: measured 28
  // components left, 133 without the removal.
  const Topology topology = build_topology(with.mesh.F, with.mesh.num_vertices());
  EXPECT_EQ(with.report.quality.components, topology.num_components);
  // The removed pieces are the components the remesh without the handling has in excess:
  // measured 28 = 133 - 105 (more than the input's 122 less 105: the manifold split separates
  // pieces that the input's non-manifold vertices join).
  EXPECT_LE(topology.num_components, without.report.quality.components - c.small_pieces + 3);
  std::vector<Eigen::AlignedBox3d> boxes(static_cast<std::size_t>(topology.num_components));
  for (Index v = 0; v < with.mesh.num_vertices(); ++v)
    boxes[static_cast<std::size_t>(topology.vertex_component[static_cast<std::size_t>(v)])].extend(
        with.mesh.V.row(v).transpose());
  for (const auto& box : boxes) EXPECT_GE(box.diagonal().norm(), 1.0 * with.report.edge_length);
  EXPECT_GE(without.report.quality.components, topology.num_components + 80);  // measured 133 vs 28
}

TEST(RemeshRawScan, KeptPiecesAreCopiedUnchanged) {
  const test::RawScan& scan = raw_bunny();
  IsotropicRemeshOptions options;
  options.small_pieces = SmallPieces::keep;
  const double L = raw_bunny_remesh(true).report.edge_length;
  const RemeshResult kept = remesh_to_edge_length(scan.mesh.V, scan.mesh.F, L, options);
  options.small_pieces = SmallPieces::remove;
  const RemeshResult removed = remesh_to_edge_length(scan.mesh.V, scan.mesh.F, L, options);
  EXPECT_TRUE(kept.report.cleanup.small_pieces_kept);
  EXPECT_EQ(kept.report.cleanup.small_pieces, removed.report.cleanup.small_pieces);
  // The kept faces are appended after the remeshed ones, with their input positions.
  ASSERT_EQ(kept.mesh.num_faces(), removed.mesh.num_faces() + kept.report.cleanup.small_piece_faces);
  EXPECT_EQ(kept.mesh.V.topRows(removed.mesh.num_vertices()), removed.mesh.V);
  std::set<std::array<double, 3>> input;
  for (Index v = 0; v < scan.mesh.num_vertices(); ++v)
    input.insert({scan.mesh.V(v, 0), scan.mesh.V(v, 1), scan.mesh.V(v, 2)});
  for (Index v = removed.mesh.num_vertices(); v < kept.mesh.num_vertices(); ++v)
    EXPECT_TRUE(input.count({kept.mesh.V(v, 0), kept.mesh.V(v, 1), kept.mesh.V(v, 2)})) << v;
  EXPECT_EQ(kept.report.quality.components, removed.report.quality.components + kept.report.cleanup.small_pieces);
}

// The acceptance of issue 31 on the raw scan: manifold, no zero-area face, no edge below 1e-4
// target edges, at most 2 % of the interior faces below quality 0.3; the report's quality is
// that of the mesh returned. Without the handling the same input gives 1-face components and
// edges of 0.03 target edges.
TEST(RemeshRawScan, GivesACleanMeshWithGoodInteriorQuality) {
  const RemeshResult& with = raw_bunny_remesh(true);
  const RemeshReport& r = with.report;
  std::cout << "[measured] quality below 0.3: interior " << r.quality.interior.fraction_below_0_3 << " of "
            << r.quality.interior_faces << ", rim " << r.quality.rim.fraction_below_0_3 << " of " << r.quality.rim_faces
            << "; min edge " << r.quality.min_edge_length / r.edge_length << " L; loops " << r.quality.boundary_loops
            << "\n";
  test::expect_clean_surface(with.mesh);
  EXPECT_EQ(r.quality.zero_area_faces, 0);
  EXPECT_EQ(r.quality.non_manifold_vertices, 0);
  EXPECT_GE(r.quality.min_edge_length, 1e-4 * r.edge_length);
  EXPECT_LE(r.quality.interior.fraction_below_0_3, 0.02);  // measured 0
  EXPECT_TRUE(r.within_tolerance);
  // The report describes the result.
  const Topology topology = build_topology(with.mesh.F, with.mesh.num_vertices());
  EXPECT_EQ(r.quality.boundary_loops, static_cast<Index>(topology.boundary_loops.size()));
  EXPECT_EQ(r.quality.interior_faces + r.quality.rim_faces, with.mesh.num_faces());
  EXPECT_EQ(r.quality.all.fraction_below_0_3,
            summarize_quality(triangle_quality(with.mesh.V, with.mesh.F)).fraction_below_0_3);
  double min_edge = std::numeric_limits<double>::infinity();
  for (Index e = 0; e < topology.num_edges(); ++e)
    min_edge =
        std::min(min_edge, (with.mesh.V.row(topology.edges(e, 0)) - with.mesh.V.row(topology.edges(e, 1))).norm());
  EXPECT_EQ(r.quality.min_edge_length, min_edge);
  // Vertices on the input surface (pieces removed, the rest projected).
  EXPECT_LT(max_distance_to_surface(with.mesh.V, raw_bunny().mesh), 1e-9 * bounding_box(with.mesh.V).diagonal());

  const RemeshReport& before = raw_bunny_remesh(false).report;
  std::cout << "[measured] without the handling: components " << before.quality.components << ", min edge "
            << before.quality.min_edge_length / before.edge_length << " L, below 0.3 "
            << before.quality.all.fraction_below_0_3 << "\n";
  EXPECT_LT(before.quality.min_edge_length, 0.05 * before.edge_length);  // measured 0.033
  EXPECT_GT(r.quality.min_edge_length, 0.05 * r.edge_length);            // measured 0.07
}

// A boundary loop shorter than short_loop_edges target edges keeps vertices at its input
// positions (about one per half target edge, at least 3) instead of being collapsed.
TEST(RemeshRawScan, ShortLoopsAreKept) {
  // A unit sphere with one small hole: the faces within 0.06 of the north pole removed.
  const Mesh sphere = test::icosphere(1.0, 5);
  std::vector<Index> kept_faces;
  for (Index f = 0; f < sphere.num_faces(); ++f) {
    bool near = false;
    for (int k = 0; k < 3; ++k)
      near = near || (sphere.V.row(sphere.F(f, k)) - Eigen::RowVector3d(0, 0, 1)).norm() < 0.06;
    if (!near) kept_faces.push_back(f);
  }
  Mesh holed;
  holed.V = sphere.V;
  holed.F.resize(static_cast<Index>(kept_faces.size()), 3);
  for (std::size_t i = 0; i < kept_faces.size(); ++i) holed.F.row(static_cast<Index>(i)) = sphere.F.row(kept_faces[i]);
  const Topology input = build_topology(holed.F, holed.num_vertices());
  ASSERT_EQ(input.boundary_loops.size(), 1u);
  double perimeter = 0;
  const std::vector<Index>& loop = input.boundary_loops.front();
  for (std::size_t i = 0; i < loop.size(); ++i)
    perimeter += (holed.V.row(loop[i]) - holed.V.row(loop[(i + 1) % loop.size()])).norm();
  const double L = 0.2;  // the loop is about 2.3 L long (measured 0.454), of 12 input edges
  ASSERT_LT(perimeter, 3 * L);
  std::set<std::array<double, 3>> rim;
  for (const Index v : loop) rim.insert({holed.V(v, 0), holed.V(v, 1), holed.V(v, 2)});

  const RemeshResult with = remesh_to_edge_length(holed.V, holed.F, L);
  EXPECT_EQ(with.report.cleanup.short_loops, 1);
  EXPECT_EQ(with.report.cleanup.held_loop_vertices, std::max<Index>(3, static_cast<Index>(perimeter / L)));
  const Topology output = build_topology(with.mesh.F, with.mesh.num_vertices());
  ASSERT_EQ(output.boundary_loops.size(), 1u);
  Index on_rim = 0;
  for (const Index v : output.boundary_loops.front())
    on_rim += rim.count({with.mesh.V(v, 0), with.mesh.V(v, 1), with.mesh.V(v, 2)}) ? 1 : 0;
  const auto loop_length = [](const Mesh& m, const std::vector<Index>& l) {
    double sum = 0;
    for (std::size_t i = 0; i < l.size(); ++i) sum += (m.V.row(l[i]) - m.V.row(l[(i + 1) % l.size()])).norm();
    return sum;
  };
  const double kept_perimeter = loop_length(with.mesh, output.boundary_loops.front());
  std::cout << "[measured] hole of perimeter " << perimeter << ": loop of " << output.boundary_loops.front().size()
            << " vertices, " << on_rim << " at input rim vertices, perimeter " << kept_perimeter << "\n";
  EXPECT_GE(on_rim, with.report.cleanup.held_loop_vertices);
  // Held at even arc lengths: a triangle inscribed in the round hole (0.83 of a circle's;
  // measured 0.365, 0.80 of the rim; CGAL's own resampling measured 0.331).
  EXPECT_GT(kept_perimeter, 0.7 * perimeter);

  IsotropicRemeshOptions off;
  off.short_loop_edges = 0;
  const RemeshResult without = remesh_to_edge_length(holed.V, holed.F, L, off);
  EXPECT_EQ(without.report.cleanup.short_loops, 0);
  const Topology collapsed = build_topology(without.mesh.F, without.mesh.num_vertices());
  ASSERT_EQ(collapsed.boundary_loops.size(), 1u);
  std::cout << "[measured] resampled instead: loop of " << collapsed.boundary_loops.front().size()
            << " vertices, perimeter " << loop_length(without.mesh, collapsed.boundary_loops.front()) << "\n";
}

// fill_hole_edges fills the loops shorter than that many target edges before remeshing: the
// sphere's small hole is closed over, a long loop is kept; off by default.
TEST(RemeshRawScan, HolesBelowTheFillLengthAreFilled) {
  const Mesh sphere = test::icosphere(1.0, 5);
  // Two holes: the faces within 0.06 of the north pole (perimeter 0.45), within 0.3 of the
  // south pole (perimeter about 1.9).
  std::vector<Index> kept_faces;
  for (Index f = 0; f < sphere.num_faces(); ++f) {
    bool near = false;
    for (int k = 0; k < 3; ++k) {
      near = near || (sphere.V.row(sphere.F(f, k)) - Eigen::RowVector3d(0, 0, 1)).norm() < 0.06;
      near = near || (sphere.V.row(sphere.F(f, k)) - Eigen::RowVector3d(0, 0, -1)).norm() < 0.3;
    }
    if (!near) kept_faces.push_back(f);
  }
  Mesh holed;
  holed.V = sphere.V;
  holed.F.resize(static_cast<Index>(kept_faces.size()), 3);
  for (std::size_t i = 0; i < kept_faces.size(); ++i) holed.F.row(static_cast<Index>(i)) = sphere.F.row(kept_faces[i]);
  ASSERT_EQ(build_topology(holed.F, holed.num_vertices()).boundary_loops.size(), 2u);
  const double L = 0.2;
  IsotropicRemeshOptions options;
  options.fill_hole_edges = 5;  // loops under 1.0: the north hole (0.45) only
  const RemeshResult filled = remesh_to_edge_length(holed.V, holed.F, L, options);
  EXPECT_EQ(filled.report.cleanup.filled_holes, 1);
  EXPECT_EQ(filled.report.quality.boundary_loops, 1);
  test::expect_clean_surface(filled.mesh);
  const RemeshResult kept = remesh_to_edge_length(holed.V, holed.F, L);
  EXPECT_EQ(kept.report.cleanup.filled_holes, 0);
  EXPECT_EQ(kept.report.quality.boundary_loops, 2);
}

// An edge shorter than 1e-4 target edges left in the result (here a protected boundary edge of
// 1e-6 of its input length) is collapsed; without that the result would keep it.
TEST(RemeshRawScan, EdgesFarBelowTheTargetAreCollapsed) {
  Mesh mesh = read_mesh(test::data_path("hemisphere.off"));
  const Topology topology = build_topology(mesh.F, mesh.num_vertices());
  // The face on the boundary edge a -> b gets a vertex p at 1e-6 of the way from a to b.
  const std::vector<Index>& loop = topology.boundary_loops.front();
  const Index a = loop[1], b = loop[0];  // loops run against their faces' edges
  Index face = -1, corner = -1;
  for (Index f = 0; f < mesh.num_faces() && face < 0; ++f)
    for (int k = 0; k < 3; ++k)
      if (mesh.F(f, k) == a && mesh.F(f, (k + 1) % 3) == b) face = f, corner = k;
  ASSERT_GE(face, 0);
  const Index c = mesh.F(face, (corner + 2) % 3), p = mesh.num_vertices();
  mesh.V.conservativeResize(p + 1, 3);
  mesh.V.row(p) = mesh.V.row(a) + 1e-6 * (mesh.V.row(b) - mesh.V.row(a));
  mesh.F.row(face) << a, p, c;
  mesh.F.conservativeResize(mesh.num_faces() + 1, 3);
  mesh.F.row(mesh.num_faces() - 1) << p, b, c;
  IsotropicRemeshOptions options;
  options.protect_boundary = true;
  const double L = 1.2 * mean_edge_length(mesh.V, topology);
  const RemeshResult result = remesh_to_edge_length(mesh.V, mesh.F, L, options);
  EXPECT_GE(result.report.cleanup.collapsed_short_edges, 1);
  EXPECT_GE(result.report.quality.min_edge_length, 1e-4 * L);
  test::expect_clean_surface(result.mesh);
  EXPECT_EQ(build_topology(result.mesh.F, result.mesh.num_vertices()).boundary_loops.size(), 1u);
}

TEST(RemeshRawScan, QualityIsSplitIntoRimAndInteriorFaces) {
  const Mesh hemisphere = read_mesh(test::data_path("hemisphere.off"));
  const RemeshQuality q = remesh_quality(hemisphere.V, hemisphere.F);
  const Topology topology = build_topology(hemisphere.F, hemisphere.num_vertices());
  Index rim = 0;
  for (Index f = 0; f < hemisphere.num_faces(); ++f)
    rim += topology.is_boundary_vertex[static_cast<std::size_t>(hemisphere.F(f, 0))] ||
                   topology.is_boundary_vertex[static_cast<std::size_t>(hemisphere.F(f, 1))] ||
                   topology.is_boundary_vertex[static_cast<std::size_t>(hemisphere.F(f, 2))]
               ? 1
               : 0;
  EXPECT_GT(rim, 0);
  EXPECT_EQ(q.rim_faces, rim);
  EXPECT_EQ(q.interior_faces, hemisphere.num_faces() - rim);
  EXPECT_EQ(q.boundary_loops, 1);
  EXPECT_EQ(q.components, 1);
  EXPECT_EQ(q.zero_area_faces, 0);
  // A closed mesh has no rim faces.
  const Mesh sphere = test::icosphere(1.0, 2);
  const RemeshQuality closed = remesh_quality(sphere.V, sphere.F);
  EXPECT_EQ(closed.rim_faces, 0);
  EXPECT_EQ(closed.interior_faces, sphere.num_faces());
  EXPECT_EQ(closed.interior.mean, closed.all.mean);
}

// Issue 31: a scan with hundreds of holes far below the target edge (docs/remesh.md). Its remesh
// has needles around the tiny holes and nowhere else; the input check counts interior faces only,
// so smooth mode takes the remesh instead of holding it as decimated, and gains.
TEST(RemeshRawScan, SmoothModeTakesARemeshWhosePoorFacesAreAllAtTinyHoles) {
  test::RawScanOptions tiny;
  tiny.subdivisions = 1;
  tiny.holes = 650;
  tiny.hole_radius_min = 0.05;
  tiny.hole_radius_max = 0.5;
  const Mesh dense = read_mesh(test::data_path("bunny.off"));
  const test::RawScan scan = test::make_raw_scan(dense, tiny);
  RemeshOptions options;
  options.target_vertices = 6000;
  const Mesh remeshed = remesh_to_vertex_count(scan.mesh.V, scan.mesh.F, options).mesh;

  const InputCheck check = check_input(remeshed.V, remeshed.F);
  const double poor_overall = summarize_quality(triangle_quality(remeshed.V, remeshed.F)).fraction_below_0_3;
  std::cout << "[measured] remesh of a scan with 650 tiny holes: below 0.3 " << poor_overall << " of all faces, "
            << check.poor_face_fraction << " of " << check.interior_faces << " interior faces (" << check.rim_faces
            << " rim faces)\n";
  EXPECT_GT(check.rim_faces, remeshed.num_faces() / 3);  // measured 5534 of 11586
  EXPECT_EQ(check.interior_faces + check.rim_faces, remeshed.num_faces());
  // Counted over all faces the remesh would look decimated (measured 4.3%)...
  EXPECT_GT(poor_overall, kMaxPoorFaceFraction);
  // ...but its interior is clean (measured 0), so it is not held.
  EXPECT_LT(check.poor_face_fraction, kMaxPoorFaceFraction / 5);
  EXPECT_EQ(check.reason, HoldReason::None);

  EnhanceOptions smooth;
  smooth.surface = EnhanceSurface::Smooth;
  const EnhanceResult result = enhance(remeshed, nullptr, smooth);
  EXPECT_EQ(result.report["fit"]["held_as_decimated"], false);
  const double before = symmetric_distance(remeshed.V, remeshed.F, dense.V, dense.F).mean();
  const double after = symmetric_distance(result.mesh.V, result.mesh.F, dense.V, dense.F).mean();
  std::cout << "[measured] smooth mode: two-sided mean distance to bunny.off " << before << " -> " << after << "\n";
  EXPECT_LT(after, 0.95 * before);  // issue 31 asks for 5%; measured -18.5%
  EXPECT_TRUE(flipped_faces(remeshed.V, result.mesh.V, remeshed.F).empty());
}

TEST(Remesh, NonManifoldInputIsRemeshedThroughItsSplit) {
  const Mesh bowtie = test::bowtie();
  SurfaceRepairs repairs;
  const Mesh result = remesh_isotropic(bowtie.V, bowtie.F, 0.25, {}, &repairs);
  test::expect_clean_surface(result);
  EXPECT_EQ(repairs.input_split.held_vertices, 1);
  EXPECT_EQ(build_topology(result.F, result.num_vertices()).num_components, 2);  // the two wings, apart
}

TEST(Remesh, RefusesBadInputAndOptions) {
  const Mesh sphere = test::icosphere(1.0, 2);
  EXPECT_THROW(remesh_isotropic(sphere.V, sphere.F, 0.0), std::invalid_argument);
  EXPECT_THROW(remesh_isotropic(sphere.V, sphere.F, std::nan("")), std::invalid_argument);
  try {  // about 7e9 vertices: refused before CGAL tries
    remesh_isotropic(sphere.V, sphere.F, 1e-4);
    FAIL() << "runaway edge length accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("(at most 50 million)"), std::string::npos) << e.what();
  }
  IsotropicRemeshOptions bad;
  bad.small_piece_edges = -1;
  EXPECT_THROW(remesh_isotropic(sphere.V, sphere.F, 0.1, bad), std::invalid_argument);
  bad = {};
  bad.short_loop_edges = std::nan("");
  EXPECT_THROW(remesh_to_edge_length(sphere.V, sphere.F, 0.1, bad), std::invalid_argument);
  RemeshOptions options;
  options.target_vertices = 0;
  EXPECT_THROW(remesh_to_vertex_count(sphere.V, sphere.F, options), std::invalid_argument);
  options.target_vertices = 100;
  options.max_attempts = 0;
  EXPECT_THROW(remesh_to_vertex_count(sphere.V, sphere.F, options), std::invalid_argument);
  // A mesh collapsed to a point has no area to divide (issue 12: "about -nan vertices").
  const Vertices point = Vertices::Zero(sphere.V.rows(), 3);
  for (const bool by_count : {true, false}) {
    try {
      if (by_count)
        remesh_to_vertex_count(point, sphere.F);
      else
        remesh_isotropic(point, sphere.F, 0.1);
      FAIL() << "zero-area mesh accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("remesh: the mesh's surface area is 0"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace vertexflow
