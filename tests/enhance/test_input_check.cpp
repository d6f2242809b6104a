// The input check of issue 30 (input_check.h) in the engine: the paper's flow and smooth mode
// hold an input that is decimated or a subdivision control mesh, with a warning and the report's
// "hold" section, and assume_on_surface runs them anyway, as vertex_flow and the smooth fit do on
// their own. The truths are made here: a QEM simplification of a data mesh has that mesh, and a
// control mesh has its CGAL Loop subdivision.
#include "shapes.h"
#include "test_support.h"

#include "vertexflow/distance.h"
#include "vertexflow/enhance.h"
#include "vertexflow/input_check.h"
#include "vertexflow/io.h"
#include "vertexflow/quality.h"
#include "vertexflow/simplify.h"
#include "vertexflow/topology.h"

#include <CGAL/Simple_cartesian.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/subdivision_method_3.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <iostream>
#include <string>
#include <vector>

namespace vertexflow {
namespace {

// The surface a control mesh stands for: `iterations` rounds of Loop subdivision (CGAL).
Mesh loop_subdivision(const Mesh& cage, int iterations) {
  using Kernel = CGAL::Simple_cartesian<double>;
  using SurfaceMesh = CGAL::Surface_mesh<Kernel::Point_3>;
  SurfaceMesh sm;
  std::vector<SurfaceMesh::Vertex_index> vertex;
  for (Index v = 0; v < cage.num_vertices(); ++v)
    vertex.push_back(sm.add_vertex(Kernel::Point_3(cage.V(v, 0), cage.V(v, 1), cage.V(v, 2))));
  for (Index f = 0; f < cage.num_faces(); ++f)
    EXPECT_NE(
        sm.add_face(vertex[static_cast<std::size_t>(cage.F(f, 0))], vertex[static_cast<std::size_t>(cage.F(f, 1))],
                    vertex[static_cast<std::size_t>(cage.F(f, 2))]),
        SurfaceMesh::null_face());
  CGAL::Subdivision_method_3::Loop_subdivision(sm, CGAL::parameters::number_of_iterations(iterations));
  Mesh out;
  out.V.resize(static_cast<Eigen::Index>(sm.number_of_vertices()), 3);
  out.F.resize(static_cast<Eigen::Index>(sm.number_of_faces()), 3);
  for (const auto v : sm.vertices()) {
    const auto& p = sm.point(v);
    out.V.row(static_cast<Eigen::Index>(v.idx())) << p.x(), p.y(), p.z();
  }
  for (const auto f : sm.faces()) {
    int k = 0;
    for (const auto v : CGAL::vertices_around_face(sm.halfedge(f), sm))
      out.F(static_cast<Eigen::Index>(f.idx()), k++) = static_cast<Index>(v.idx());
  }
  return out;
}

double mean_distance(const Mesh& mesh, const Mesh& truth) {
  return symmetric_distance(mesh.V, mesh.F, truth.V, truth.F).mean();
}

EnhanceOptions smooth_mode() {
  EnhanceOptions o;
  o.surface = EnhanceSurface::Smooth;
  return o;
}

// spot.obj simplified by QEM to 10% of its faces (586): its vertices lie off spot's surface.
struct DecimatedSpot {
  Mesh truth = read_mesh(test::data_path("spot.obj"));
  Mesh input = [this] {
    SimplifyOptions options;
    options.target_ratio = 0.1;
    const Mesh simplified = simplify(truth.V, truth.F, options).mesh;
    return Mesh{simplified.V, simplified.F, {}, {}};
  }();
};

// The measures of input_check.h on both kinds of input and on meshes whose vertices lie on the
// surface: a remesh, a scan, subdivision output.
TEST(InputCheck, MeasuresDecimationAndControlMeshes) {
  const DecimatedSpot spot;
  const InputCheck decimated = check_input(spot.input.V, spot.input.F);
  EXPECT_EQ(decimated.reason, HoldReason::Decimated);
  std::cout << "[measured] spot at 10%: faces below 0.3 " << decimated.poor_face_fraction << "\n";
  EXPECT_GT(decimated.poor_face_fraction, kMaxPoorFaceFraction);  // measured 0.060

  const Mesh suzanne = read_mesh(test::data_path("suzanne.obj"));
  const InputCheck cage = check_input(suzanne.V, suzanne.F);
  EXPECT_EQ(cage.reason, HoldReason::ControlMesh);
  std::cout << "[measured] suzanne: sharp edges " << cage.sharp_edge_fraction << ", faces below 0.3 "
            << cage.poor_face_fraction << "\n";
  EXPECT_GT(cage.sharp_edge_fraction, 2 * kMaxSharpEdgeFraction);  // measured 0.290
  EXPECT_LT(cage.poor_face_fraction, kMaxPoorFaceFraction);        // measured 0.0145: not decimated

  // Its subdivision is smooth: the same surface, sampled on it.
  const Mesh limit = loop_subdivision(suzanne, 2);
  const InputCheck subdivided = check_input(limit.V, limit.F);
  EXPECT_EQ(subdivided.reason, HoldReason::None);
  std::cout << "[measured] suzanne's Loop subdivision x2: sharp edges " << subdivided.sharp_edge_fraction << "\n";
  EXPECT_LT(subdivided.sharp_edge_fraction, kMaxSharpEdgeFraction / 2);

  for (const std::string name : {"bunny_uniform.off", "horse-48k.ply", "fandisk.off", "spot.obj"}) {
    const Mesh mesh = read_mesh(test::data_path(name));
    const InputCheck check = check_input(mesh.V, mesh.F);
    EXPECT_EQ(check.reason, HoldReason::None) << name;
    std::cout << "[measured] " << name << ": faces below 0.3 " << check.poor_face_fraction << ", sharp edges "
              << check.sharp_edge_fraction << "\n";
    // measured at most 0.0145 (horse) and 0.037 (fandisk's creases)
    EXPECT_LT(check.poor_face_fraction, kMaxPoorFaceFraction / 1.5) << name;
    EXPECT_LT(check.sharp_edge_fraction, kMaxSharpEdgeFraction / 2) << name;
  }
  EXPECT_THROW(check_input(suzanne.V, suzanne.F, {1.5, 0.1}), std::invalid_argument);
}

// The poor-face share counts interior faces only (no corner on a boundary edge): needles at a
// rim are what a remesh leaves around holes far below its edge, not the mark of decimation. A
// flat 30 x 30 grid gets needles by moving one row of vertices to 2% of a cell from a line of
// the grid: at the border (rim faces only) it is not held, one row inside it is.
TEST(InputCheck, CountsPoorFacesAwayFromTheBoundary) {
  constexpr int n = 30;
  const auto grid_with_needles_at_row = [&](int row) {
    Mesh grid = test::height_field(1.0, n, [](double, double) { return 0.0; });
    const double cell = 2.0 / n;
    for (int j = 0; j <= n; ++j) grid.V(row * (n + 1) + j, 0) = grid.V((row - 1) * (n + 1) + j, 0) + 0.02 * cell;
    return grid;
  };
  const Mesh at_rim = grid_with_needles_at_row(1);
  const InputCheck rim = check_input(at_rim.V, at_rim.F);
  const double overall = summarize_quality(triangle_quality(at_rim.V, at_rim.F)).fraction_below_0_3;
  EXPECT_EQ(rim.rim_faces, 2 * (4 * n - 4));  // both faces of each of the 4n - 4 cells on the border
  EXPECT_EQ(rim.interior_faces + rim.rim_faces, at_rim.num_faces());
  EXPECT_GT(overall, kMaxPoorFaceFraction);  // 2n needles of 2n^2 faces: 3.3%
  EXPECT_EQ(rim.poor_face_fraction, 0);
  EXPECT_EQ(rim.reason, HoldReason::None);

  const Mesh inside = grid_with_needles_at_row(2);
  const InputCheck held = check_input(inside.V, inside.F);
  EXPECT_GT(held.poor_face_fraction, kMaxPoorFaceFraction);
  EXPECT_EQ(held.reason, HoldReason::Decimated);

  // A closed mesh has no rim: the share is over every face.
  const Mesh spot = read_mesh(test::data_path("spot.obj"));
  const InputCheck closed = check_input(spot.V, spot.F);
  EXPECT_EQ(closed.rim_faces, 0);
  EXPECT_EQ(closed.poor_face_fraction, summarize_quality(triangle_quality(spot.V, spot.F)).fraction_below_0_3);
}

// With the caller's topology the check takes the edges from it instead of finding them again:
// every measure the same, on a closed mesh, one with a rim, a control mesh, a decimated mesh and
// a non-manifold one (three faces on an edge: that topology is not used, the faces are).
TEST(InputCheck, TopologyGivesTheSameMeasures) {
  Mesh fan = test::height_field(1.0, 6, [](double x, double y) { return 0.3 * x * y; });
  const Index apex = fan.num_vertices();
  fan.V.conservativeResize(apex + 1, 3);
  fan.V.row(apex) << 0.0, 0.0, 1.0;
  const Topology grid = build_topology(fan.F, apex);
  const auto interior = std::find(grid.edge_face_count.begin(), grid.edge_face_count.end(), 2);
  ASSERT_NE(interior, grid.edge_face_count.end());
  const Index e = static_cast<Index>(interior - grid.edge_face_count.begin());
  fan.F.conservativeResize(fan.num_faces() + 1, 3);
  fan.F.row(fan.num_faces() - 1) << grid.edges(e, 0), grid.edges(e, 1), apex;  // a third face on the edge
  const Mesh cage = read_mesh(test::data_path("suzanne.obj"));
  const std::vector<Mesh> meshes{read_mesh(test::data_path("spot.obj")),
                                 test::height_field(1.0, 12, [](double x, double y) { return x * x - y * y; }), cage,
                                 DecimatedSpot().input, fan};
  for (std::size_t k = 0; k < meshes.size(); ++k) {
    const Mesh& mesh = meshes[k];
    const Topology topology = build_topology(mesh.F, mesh.num_vertices());
    const InputCheck faces = check_input(mesh.V, mesh.F), edges = check_input(mesh.V, mesh.F, {}, &topology);
    EXPECT_EQ(edges.poor_face_fraction, faces.poor_face_fraction) << k;
    EXPECT_EQ(edges.interior_faces, faces.interior_faces) << k;
    EXPECT_EQ(edges.rim_faces, faces.rim_faces) << k;
    EXPECT_EQ(edges.sharp_edge_fraction, faces.sharp_edge_fraction) << k;
    EXPECT_EQ(edges.interior_edges, faces.interior_edges) << k;
    EXPECT_EQ(edges.reason, faces.reason) << k;
    EXPECT_GT(faces.interior_edges, 0) << k;
  }
  // The cases differ where it matters: a rim, sharp edges, poor faces, a non-manifold edge.
  EXPECT_GT(check_input(meshes[1].V, meshes[1].F).rim_faces, 0);
  EXPECT_EQ(check_input(cage.V, cage.F).reason, HoldReason::ControlMesh);
  EXPECT_EQ(check_input(meshes[3].V, meshes[3].F).reason, HoldReason::Decimated);
  EXPECT_FALSE(build_topology(fan.F, fan.num_vertices()).non_manifold_edges.empty());
}

// The decimated input: the flow (and its density passes) and smooth mode hold it, saying why;
// assume_on_surface flows it as vertex_flow does, and that is much worse against the dense mesh.
TEST(InputCheck, HoldsDecimatedInputUnlessAssumedOnSurface) {
  const DecimatedSpot spot;
  EnhanceOptions density;
  density.flow.density.passes = 5;
  for (const EnhanceOptions& options : {EnhanceOptions{}, density, smooth_mode()}) {
    const EnhanceResult held = enhance(spot.input, nullptr, options);
    EXPECT_EQ(held.mesh.V, spot.input.V);
    ASSERT_EQ(held.warnings.size(), 1u);
    EXPECT_NE(held.warnings[0].find("decimated"), std::string::npos) << held.warnings[0];
    EXPECT_NE(held.warnings[0].find("--reference DENSE"), std::string::npos) << held.warnings[0];
    EXPECT_NE(held.warnings[0].find("--assume-on-surface"), std::string::npos) << held.warnings[0];
    const nlohmann::json& hold = held.report["hold"];
    EXPECT_TRUE(hold["held"]);
    EXPECT_EQ(hold["reason"], "decimated");
    EXPECT_GT(hold["poor_face_fraction"].get<double>(), kMaxPoorFaceFraction);
    EXPECT_EQ(hold["thresholds"]["poor_face_fraction"], kMaxPoorFaceFraction);
    EXPECT_NE(held.provenance.find("held: decimated"), std::string::npos) << held.provenance;
  }

  EnhanceOptions assumed;
  assumed.assume_on_surface = true;
  const EnhanceResult flowed = enhance(spot.input, nullptr, assumed);
  EXPECT_TRUE(flowed.warnings.empty());
  EXPECT_FALSE(flowed.report["hold"]["held"]);
  EXPECT_EQ(flowed.report["hold"]["reason"], "decimated");  // what the flag overrode
  EXPECT_EQ(flowed.mesh.V, vertex_flow(spot.input.V, spot.input.F).V);
  // Why it is held: measured 3.30e-3 -> 6.74e-3 of spot's units (+104%).
  const double before = mean_distance(spot.input, spot.truth), after = mean_distance(flowed.mesh, spot.truth);
  std::cout << "[measured] spot at 10%, flowed anyway: mean distance " << before << " -> " << after << "\n";
  EXPECT_GT(after, 1.4 * before) << before << " -> " << after;
}

// The control mesh of a subdivision surface: held by the flow and smooth mode; smooth mode fitted
// anyway moves it away from its limit surface. The subdivided mesh itself is not held.
TEST(InputCheck, HoldsControlMeshUnlessAssumedOnSurface) {
  const Mesh suzanne = read_mesh(test::data_path("suzanne.obj"));
  const Mesh limit = loop_subdivision(suzanne, 3);
  for (const EnhanceOptions& options : {EnhanceOptions{}, smooth_mode()}) {
    const EnhanceResult held = enhance(suzanne, nullptr, options);
    EXPECT_EQ(held.mesh.V, suzanne.V);
    ASSERT_EQ(held.warnings.size(), 1u);
    EXPECT_NE(held.warnings[0].find("subdivision control mesh"), std::string::npos) << held.warnings[0];
    EXPECT_NE(held.warnings[0].find("--reference DENSE"), std::string::npos) << held.warnings[0];
    EXPECT_TRUE(held.report["hold"]["held"]);
    EXPECT_EQ(held.report["hold"]["reason"], "subdivision control mesh");
    EXPECT_GT(held.report["hold"]["sharp_edge_fraction"].get<double>(), kMaxSharpEdgeFraction);
  }
  EXPECT_TRUE(enhance(suzanne, nullptr, smooth_mode()).report["fit"]["held_as_control_mesh"]);

  EnhanceOptions assumed = smooth_mode();
  assumed.assume_on_surface = true;
  const EnhanceResult fitted = enhance(suzanne, nullptr, assumed);
  EXPECT_TRUE(fitted.warnings.empty());
  EXPECT_FALSE(fitted.report["hold"]["held"]);
  SmoothFitOptions anyway;
  anyway.max_poor_face_fraction = anyway.max_sharp_edge_fraction = 1;
  EXPECT_EQ(fitted.mesh.V, fit_to_smooth_surface(suzanne.V, suzanne.F, anyway).V);
  // Why it is held: measured 0.0146 -> 0.0205 to the Loop limit (+41%).
  const double before = mean_distance(suzanne, limit), after = mean_distance(fitted.mesh, limit);
  std::cout << "[measured] suzanne, smooth mode anyway: mean distance to the Loop limit " << before << " -> " << after
            << "\n";
  EXPECT_GT(after, 1.2 * before) << before << " -> " << after;
  // The flow anyway is vertex_flow.
  EnhanceOptions flow_anyway;
  flow_anyway.assume_on_surface = true;
  EXPECT_EQ(enhance(suzanne, nullptr, flow_anyway).mesh.V, vertex_flow(suzanne.V, suzanne.F).V);

  // The subdivided surface is sampled on itself: fitted, not held.
  const Mesh subdivided = loop_subdivision(suzanne, 2);
  const EnhanceResult smooth = enhance(subdivided, nullptr, smooth_mode());
  EXPECT_TRUE(smooth.warnings.empty());
  EXPECT_FALSE(smooth.report["hold"]["held"]);
  EXPECT_TRUE(smooth.report["hold"]["reason"].is_null());
  EXPECT_NE(smooth.mesh.V, subdivided.V);
}

// The methods that do not assume the vertices on the surface are not checked.
TEST(InputCheck, ReferenceAndUnsharpModesDoNotHold) {
  const DecimatedSpot spot;
  const ReferenceSurface reference(spot.truth.V, spot.truth.F, "spot.obj");
  const EnhanceResult fitted = enhance(spot.input, &reference, EnhanceOptions{});
  EXPECT_FALSE(fitted.report.contains("hold"));
  EXPECT_NE(fitted.mesh.V, spot.input.V);
  EnhanceOptions unsharp;
  unsharp.method = EnhanceMethod::Unsharp;
  EXPECT_NE(enhance(spot.input, nullptr, unsharp).mesh.V, spot.input.V);
  EnhanceOptions refused = unsharp;
  refused.assume_on_surface = true;
  EXPECT_THROW(enhance(spot.input, nullptr, refused), EnhanceOptionError);
}

}  // namespace
}  // namespace vertexflow
