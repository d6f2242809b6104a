// Levels of detail fitted to their dense mesh (lod.h): budgets, monotone face counts, no flipped
// face, boundaries kept, the fit closer to the dense mesh than QEM alone, the better of the two
// kept, and the same bytes for any thread count.
#include "boundary_points.h"
#include "shapes.h"
#include "test_support.h"

#include "vertexflow/edge_flips.h"
#include "vertexflow/io.h"
#include "vertexflow/lod.h"
#include "vertexflow/topology.h"

#include <gtest/gtest.h>

#include <iostream>

#include <algorithm>
#include <array>
#include <set>
#include <stdexcept>

namespace vertexflow {
namespace {

using test::boundary_points;
using test::Point;

// Fewer area samples than the default: the figures the tests compare move by well under their
// tolerances (measured below), and the tests run in a few seconds.
LodOptions quick(std::vector<double> percent) {
  LodOptions options;
  options.percent = std::move(percent);
  options.sampling.samples = 50000;
  return options;
}

TEST(LodBudgets, PercentAndFacesAndTheirErrors) {
  EXPECT_EQ(lod_face_budgets(1000, quick({50, 25, 10, 0.01})), (std::vector<Index>{500, 250, 100, 1}));
  LodOptions faces = quick({});
  faces.faces = {600, 30};
  EXPECT_EQ(lod_face_budgets(1000, faces), (std::vector<Index>{600, 30}));
  EXPECT_THROW(lod_face_budgets(1000, quick({})), std::invalid_argument);           // no level
  EXPECT_THROW(lod_face_budgets(1000, quick({25, 50})), std::invalid_argument);     // not decreasing
  EXPECT_THROW(lod_face_budgets(1000, quick({10, 10.01})), std::invalid_argument);  // one count twice
  EXPECT_THROW(lod_face_budgets(1000, quick({100})), std::invalid_argument);        // not below D
  EXPECT_THROW(lod_face_budgets(1000, quick({-1})), std::invalid_argument);
  faces.faces = {1000};
  EXPECT_THROW(lod_face_budgets(1000, faces), std::invalid_argument);
}

// in_morton_order: the same triangles, each with its orientation, its vertices and faces along
// the curve, from a mesh whose order was shuffled.
TEST(LodOrder, SameTrianglesAlongTheCurve) {
  const Mesh sphere = test::icosphere(1.0, 4);
  Mesh shuffled = test::renumbered(sphere, 3, false).mesh;
  shuffled.comments = {"kept"};
  const Mesh ordered = in_morton_order(shuffled);
  // Each face as its corners' positions, rotated to start at its smallest: orientation kept.
  const auto triangles = [](const Mesh& m) {
    std::vector<std::array<std::array<double, 3>, 3>> out;
    for (Index f = 0; f < m.num_faces(); ++f) {
      std::array<std::array<double, 3>, 3> t;
      for (int c = 0; c < 3; ++c)
        t[static_cast<std::size_t>(c)] = {m.V(m.F(f, c), 0), m.V(m.F(f, c), 1), m.V(m.F(f, c), 2)};
      std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
      out.push_back(t);
    }
    std::sort(out.begin(), out.end());
    return out;
  };
  EXPECT_EQ(triangles(ordered), triangles(shuffled));
  EXPECT_EQ(ordered.comments, shuffled.comments);
  // Sorting again changes nothing, and the mesh in its own order comes out the same: the
  // result does not depend on the order it is given in.
  const Mesh again = in_morton_order(ordered), from_sphere = in_morton_order(sphere);
  EXPECT_EQ(again.V, ordered.V);
  EXPECT_EQ(again.F, ordered.F);
  EXPECT_EQ(from_sphere.V, ordered.V);
  EXPECT_EQ(from_sphere.F, ordered.F);
  EXPECT_NE(ordered.V, shuffled.V);
  Mesh broken = shuffled;
  broken.F(5, 1) = shuffled.num_vertices();
  EXPECT_THROW((void)in_morton_order(broken), std::invalid_argument);
}

// max-planck-5k (a real head scan at the paper's resolution, 10,540 faces): every level within one
// face of its budget and below the one before, no face turned over by the fit, and the fit closer
// to the dense mesh than QEM alone at every level. Measured mean gains (1 - fitted / QEM) at 50%,
// 20%, 5%: 2.9%, 8.2%, 14.0% over the chain's own QEM (the native one, whose area weights
// already keep the chain closer: with CGAL's QEM in the chain the gains were 9.4%, 15.6%, 21.0%
// and the fitted levels 13%, 11% and 8% farther from the dense mesh); the bounds are about half.
TEST(Lod, LevelsAreMonotoneUnflippedAndCloserThanQem) {
  constexpr double kMinGain[] = {0.015, 0.04, 0.07};
  const Mesh dense = read_mesh(test::data_path("max-planck-5k.obj"));
  const Mesh ordered = in_morton_order(dense);
  const LodOptions options = quick({50, 20, 5});
  const std::vector<Index> budgets = lod_face_budgets(dense.num_faces(), options);
  std::vector<int> seen;
  const std::vector<LodLevel> levels =
      lod(dense, options, {}, [&](const LodLevel& level) { seen.push_back(level.report.level); });
  ASSERT_EQ(levels.size(), 3u);
  EXPECT_EQ(seen, (std::vector<int>{1, 2, 3}));
  Index previous_faces = dense.num_faces();
  for (std::size_t i = 0; i < levels.size(); ++i) {
    const LodLevelReport& r = levels[i].report;
    SCOPED_TRACE(r.level);
    EXPECT_EQ(r.target_faces, budgets[i]);
    EXPECT_EQ(r.faces, levels[i].mesh.num_faces());
    EXPECT_GE(r.faces, budgets[i]);
    EXPECT_LE(r.faces, budgets[i] + 1);
    EXPECT_LT(r.faces, previous_faces);
    EXPECT_EQ(r.input_faces, previous_faces);
    previous_faces = r.faces;
    EXPECT_EQ(r.flipped_faces, 0);
    EXPECT_FALSE(r.kept_qem);
    EXPECT_FALSE(r.fit_skipped);
    EXPECT_GT(r.min_quality, 0);
    EXPECT_GT(r.qem.hausdorff, 0);
    EXPECT_GT(r.fitted.hausdorff, 0);
    // The level as kept is the fitted one, measured again independently against D in the order
    // the chain ran it (lod.h: in_morton_order; D's samples depend on its face order).
    const LodDistance again = lod_distance(levels[i].mesh, ReferenceSurface(ordered.V, ordered.F), options.sampling);
    EXPECT_EQ(again.mean, r.fitted.mean);
    EXPECT_LT(r.fitted.mean, (1 - kMinGain[i]) * r.qem.mean) << r.fitted.mean << " vs " << r.qem.mean;
  }
}

// camelhead (one boundary loop): every level keeps the loop's vertices at their input positions
// (simplify.h's keep_boundary, and the fit holds boundary vertices), with edge flips too, which
// also leave no face turned over. The chain is made from the level before: level 2's input is
// level 1 as kept.
TEST(Lod, BoundaryLoopsStayExactWithEdgeFlips) {
  const Mesh dense = read_mesh(test::data_path("camelhead.off"));
  const std::set<Point> dense_boundary = boundary_points(dense);
  LodOptions options = quick({20, 5});
  options.edge_flips = true;
  const ReferenceSurface reference(dense.V, dense.F);
  const std::vector<LodLevel> levels = lod(reference, options);
  ASSERT_EQ(levels.size(), 2u);
  Index flips = 0;
  for (const LodLevel& level : levels) {
    const std::set<Point> boundary = boundary_points(level.mesh);
    EXPECT_FALSE(boundary.empty());
    for (const Point& p : boundary) EXPECT_TRUE(dense_boundary.count(p)) << p[0] << " " << p[1] << " " << p[2];
    EXPECT_EQ(level.report.flipped_faces, 0);
    flips += level.report.edge_flips;
  }
  EXPECT_GT(flips, 0);  // the flips ran (measured: 201 and 35)
  // Level 2 again, from level 1 as kept: the same bytes.
  const LodLevel again = lod_level(levels[0].mesh, reference, levels[1].report.target_faces, 2, options);
  EXPECT_EQ(again.mesh.V, levels[1].mesh.V);
  EXPECT_EQ(again.mesh.F, levels[1].mesh.F);
}

// With edge flips the refits after each cycle of flips are guarded against their own start, not
// against the QEM face whose index a flipped face took; on rocker-arm's chain a refit at 2% and
// at 1% turned one such face past 90 degrees, and lod reported it. flip_and_refit (enhance.cpp)
// now refuses such a refit: 0 turned faces at every level.
TEST(Lod, EdgeFlipsTurnNoFaceAgainstItsQemFace) {
  const Mesh dense = read_mesh(test::data_path("rocker-arm.obj"));
  LodOptions options = quick({50, 25, 10, 5, 2, 1});
  options.edge_flips = true;
  const std::vector<LodLevel> levels = lod(dense, options);
  Index refused = 0;
  for (const LodLevel& level : levels) {
    SCOPED_TRACE(level.report.level);
    EXPECT_EQ(level.report.flipped_faces, 0);
    for (const auto& cycle : level.report.enhance["edge_flips"]["cycles"])
      refused += cycle.value("refit_refused_turned_faces", Index{0});
  }
  std::cout << "[measured] rocker-arm lod --edge-flips: faces a refused refit would have turned: " << refused
            << "\n";  // measured 2: one at 2%, one at 1%
}

// The level as kept measures the smaller of QEM alone's and the fit's mean distance; without the
// rule it is the fitted level. (No real mesh found where the fit measures worse: spot's fit at
// 10%, with the fit's samples cut to 0.05 per vertex or its membrane weighted 1000, still gains.)
TEST(Lod, KeepsTheBetterOfTheTwo) {
  const Mesh dense = read_mesh(test::data_path("spot.obj"));
  const ReferenceSurface reference(dense.V, dense.F);
  for (const bool rule : {true, false}) {
    LodOptions options = quick({10});
    options.keep_better_of_two = rule;
    const LodLevel level = lod_level(Mesh{dense.V, dense.F, {}, {}}, reference, 586, 1, options);
    const LodDistance kept = lod_distance(level.mesh, reference, options.sampling);
    const LodLevelReport& r = level.report;
    EXPECT_EQ(kept.mean, rule ? std::min(r.qem.mean, r.fitted.mean) : r.fitted.mean);
    EXPECT_EQ(r.kept_qem, rule && r.qem.mean < r.fitted.mean);
  }
}

// A perforated plate (flat faces cut into 6 x 6 quads each): QEM to 30% of its faces collapses
// within its planes and along its creases, so the level lies on the plate up to rounding and is
// not fitted (lod.h); it is QEM alone, and says so. Measured: 1,344 faces -> 404, QEM's RMS
// distance 5.8e-17 (the plate's diagonal is 4.2).
TEST(Lod, ExactLevelsAreNotFitted) {
  const Mesh plate = test::perforated_plate(1, 6, 0.2, true);
  const ReferenceSurface reference(plate.V, plate.F);
  const LodOptions options = quick({30});
  const Index budget = lod_face_budgets(plate.num_faces(), options)[0];
  const LodLevel level = lod_level(plate, reference, budget, 1, options);
  const LodLevelReport& r = level.report;
  EXPECT_LE(r.faces, budget + 1);
  EXPECT_LE(r.qem.rms, kLodExactRelative * bounding_box(plate.V).diagonal());
  EXPECT_TRUE(r.fit_skipped);
  EXPECT_TRUE(r.kept_qem);
  EXPECT_EQ(r.fitted.mean, r.qem.mean);
  EXPECT_TRUE(r.enhance.is_null());
  EXPECT_EQ(r.fit_seconds, 0);
  EXPECT_TRUE(level.mesh.comments.empty());  // no fit, no provenance line
}

// The chain's overlapped steps (lod.h): a level asked for the next budget returns the fitted
// level simplified to it, the same bytes as simplify() makes from the level afterwards, and the
// chain lod() makes through them is the chain made one step after another. A simplification
// of another input or budget is refused; a level that is not fitted has none to hand on.
TEST(Lod, OverlappedStepsGiveTheSameLevels) {
  const Mesh dense = read_mesh(test::data_path("spot.obj"));
  const ReferenceSurface reference(dense.V, dense.F);
  const LodOptions options = quick({30, 10, 4});
  const std::vector<Index> budgets = lod_face_budgets(dense.num_faces(), options);
  const std::vector<LodLevel> chain = lod(reference, options);
  ASSERT_EQ(chain.size(), budgets.size());
  Mesh previous = dense;
  for (std::size_t i = 0; i < budgets.size(); ++i) {
    SCOPED_TRACE(i);
    const Index next = i + 1 < budgets.size() ? budgets[i + 1] : 0;
    LodLevel step = lod_level(previous, reference, budgets[i], static_cast<int>(i + 1), options, {}, next);
    EXPECT_EQ(step.mesh.V, chain[i].mesh.V);
    EXPECT_EQ(step.mesh.F, chain[i].mesh.F);
    EXPECT_EQ(step.report.fitted.mean, chain[i].report.fitted.mean);
    EXPECT_EQ(step.report.qem.hausdorff, chain[i].report.qem.hausdorff);
    EXPECT_FALSE(chain[i].next_simplified.has_value());  // handed on to the next level
    if (next > 0) {
      ASSERT_FALSE(step.report.kept_qem);  // spot's levels are all fitted (measured)
      ASSERT_TRUE(step.next_simplified.has_value());
      SimplifyOptions so;
      so.target_faces = next;
      so.method = options.simplify_method;
      const SimplifyResult afterwards = simplify(step.mesh.V, step.mesh.F, so);
      EXPECT_EQ(step.next_simplified->mesh.V, afterwards.mesh.V);
      EXPECT_EQ(step.next_simplified->mesh.F, afterwards.mesh.F);
      EXPECT_EQ(step.next_simplified->report.target_faces, next);
      EXPECT_EQ(step.next_simplified->report.input_faces, step.mesh.num_faces());
    } else {
      EXPECT_FALSE(step.next_simplified.has_value());
    }
    previous = std::move(step.mesh);
  }
  // The first level's simplification handed to a level of another budget, or of another input.
  LodLevel first = lod_level(dense, reference, budgets[0], 1, options, {}, budgets[1]);
  ASSERT_TRUE(first.next_simplified.has_value());
  EXPECT_THROW((void)lod_level(first.mesh, reference, budgets[2], 2, options, {}, 0, first.next_simplified),
               std::invalid_argument);
  EXPECT_THROW((void)lod_level(dense, reference, budgets[1], 2, options, {}, 0, first.next_simplified),
               std::invalid_argument);
  // A level that QEM puts on the plate exactly is not fitted, and hands nothing on.
  const Mesh plate = test::perforated_plate(1, 6, 0.2, true);
  const ReferenceSurface plate_surface(plate.V, plate.F);
  const LodLevel exact = lod_level(plate, plate_surface, 404, 1, options, {}, 200);
  EXPECT_TRUE(exact.report.fit_skipped);
  EXPECT_FALSE(exact.next_simplified.has_value());
}

// Identical bytes for 1 and 2 threads (docs/architecture.md's rule), levels and figures.
TEST(Lod, SameBytesForAnyThreadCount) {
  const Mesh dense = read_mesh(test::data_path("spot.obj"));
  const LodOptions options = quick({30, 10});
  const auto one = test::with_threads(1, [&] { return lod(dense, options); });
  const auto two = test::with_threads(2, [&] { return lod(dense, options); });
  ASSERT_EQ(one.size(), two.size());
  for (std::size_t i = 0; i < one.size(); ++i) {
    EXPECT_EQ(one[i].mesh.V, two[i].mesh.V);
    EXPECT_EQ(one[i].mesh.F, two[i].mesh.F);
    EXPECT_EQ(one[i].report.fitted.mean, two[i].report.fitted.mean);
    EXPECT_EQ(one[i].report.qem.hausdorff, two[i].report.qem.hausdorff);
  }
}

}  // namespace
}  // namespace vertexflow
