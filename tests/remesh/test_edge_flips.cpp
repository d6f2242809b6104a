// Data-dependent edge flips (edge_flips.h): on a roof whose ridge the faces cut across, exactly
// the faces across the ridge flip and the mesh becomes the roof; the promises (no fold, the
// quality floor, manifold, same vertices) on a real mesh; invariance and determinism.
#include "shapes.h"
#include "test_support.h"

#include "vertexflow/distance.h"
#include "vertexflow/edge_flips.h"
#include "vertexflow/fit.h"
#include "vertexflow/io.h"
#include "vertexflow/quality.h"
#include "vertexflow/topology.h"

#include <gtest/gtest.h>

#include <iostream>

namespace vertexflow {
namespace {

TEST(EdgeFlips, RoofFacesCutAcrossTheRidgeFlipOntoIt) {
  const int n = 8;
  const Mesh coarse = test::roof(n, true), exact = test::roof(4 * n, false);
  const DistanceQuery target(exact.V, exact.F);
  const EdgeFlipResult result = flip_edges_toward(coarse.V, coarse.F, target);
  std::cout << "[measured] roof: " << result.report.flips << " flips in " << result.report.passes << " passes, RMS "
            << result.report.rms_before << " -> " << result.report.rms_after << "\n";
  // The n squares on the ridge flip, and no other: off the ridge each square is planar.
  EXPECT_EQ(result.report.flips, n);
  EXPECT_GT(result.report.rms_before, 1e-3);  // measured 0.0080
  EXPECT_LT(result.report.rms_after, 1e-12);
  // Flipped to the ridge diagonal: the faces of a mesh triangulated along the ridge, as sets.
  const Mesh along = test::roof(n, false);
  auto sorted_faces = [](const Faces& F) {
    std::vector<std::array<Index, 3>> faces;
    for (Index f = 0; f < F.rows(); ++f) {
      std::array<Index, 3> face{F(f, 0), F(f, 1), F(f, 2)};
      std::rotate(face.begin(), std::min_element(face.begin(), face.end()), face.end());  // keeps the winding
      faces.push_back(face);
    }
    std::sort(faces.begin(), faces.end());
    return faces;
  };
  const auto got = sorted_faces(result.F), want = sorted_faces(along.F);
  // Only the ridge squares are compared: elsewhere both diagonals lie on the roof.
  Index ridge_faces = 0;
  for (const auto& face : want) {
    const double x0 = coarse.V(face[0], 0) - coarse.V(face[0], 1), x1 = coarse.V(face[1], 0) - coarse.V(face[1], 1),
                 x2 = coarse.V(face[2], 0) - coarse.V(face[2], 1);
    const bool on_ridge = (std::abs(x0) < 1e-12) + (std::abs(x1) < 1e-12) + (std::abs(x2) < 1e-12) == 2;
    if (!on_ridge) continue;
    ++ridge_faces;
    EXPECT_TRUE(std::binary_search(got.begin(), got.end(), face)) << face[0] << " " << face[1] << " " << face[2];
  }
  EXPECT_EQ(ridge_faces, 2 * n);
  EXPECT_EQ(faces_turned_over(coarse.V, coarse.F, coarse.V, result.F), 0);
}

// Reference mode's result on bunny_uniform flipped towards bunny.off: closer to it, and the
// promises: no face turned over against its slot, none below the floor, still manifold and
// closed, the same vertices and face count.
TEST(EdgeFlips, FittedBunnyComesCloserAndKeepsThePromises) {
  const Mesh coarse = read_mesh(test::data_path("bunny_uniform.off"));
  const Mesh dense = read_mesh(test::data_path("bunny.off"));
  const Vertices fitted = fit_to_reference(coarse.V, coarse.F, dense.V, dense.F).V;
  const DistanceQuery target(dense.V, dense.F);
  Vertices slots(coarse.F.rows(), 3);
  for (Index f = 0; f < coarse.F.rows(); ++f) slots.row(f) = face_normal(coarse.V, coarse.F, f).transpose();
  const EdgeFlipResult result = flip_edges_toward(fitted, coarse.F, target, {}, &slots);
  std::cout << "[measured] fitted bunny: " << result.report.flips << " flips, RMS " << result.report.rms_before
            << " -> " << result.report.rms_after << "\n";
  EXPECT_GT(result.report.flips, 1000);                                 // measured 2792
  EXPECT_LT(result.report.rms_after, 0.95 * result.report.rms_before);  // measured 0.88
  EXPECT_EQ(result.F.rows(), coarse.F.rows());
  EXPECT_EQ(faces_turned_over(coarse.V, coarse.F, fitted, result.F), 0);
  const Eigen::VectorXd before = triangle_quality(fitted, coarse.F), after = triangle_quality(fitted, result.F);
  EXPECT_GE(after.minCoeff(), std::min(0.3, before.minCoeff()) - 1e-12);
  const Topology topology = build_topology(result.F, coarse.V.rows());
  EXPECT_TRUE(topology.non_manifold_edges.empty());
  EXPECT_EQ(std::count(topology.is_boundary_vertex.begin(), topology.is_boundary_vertex.end(), 1), 0);
}

TEST(EdgeFlips, InvariantAndDeterministic) {
  const Mesh coarse = test::roof(10, true);
  const Mesh exact = test::roof(40, false);
  const EdgeFlipResult one =
      test::with_threads(1, [&] { return flip_edges_toward(coarse.V, coarse.F, DistanceQuery(exact.V, exact.F)); });
  const EdgeFlipResult two =
      test::with_threads(2, [&] { return flip_edges_toward(coarse.V, coarse.F, DistanceQuery(exact.V, exact.F)); });
  EXPECT_EQ(one.F, two.F);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.9, Eigen::Vector3d(1, -2, 1).normalized()).toRotationMatrix();
  auto move = [&](const Vertices& X) -> Vertices {
    return ((3.0 * X * R.transpose()).rowwise() + Eigen::RowVector3d(1, 2, -5)).eval();
  };
  const EdgeFlipResult moved = flip_edges_toward(move(coarse.V), coarse.F, DistanceQuery(move(exact.V), exact.F));
  EXPECT_EQ(moved.F, one.F);
  EXPECT_EQ(moved.report.flips, one.report.flips);
}

TEST(EdgeFlips, TurnedOverFacesAreCountedAndBadOptionsThrow) {
  const Mesh mesh = test::roof(4, true);
  Faces reversed = mesh.F;
  reversed.row(3) = mesh.F.row(3).reverse();
  reversed.row(7) = mesh.F.row(7).reverse();
  EXPECT_EQ(faces_turned_over(mesh.V, mesh.F, mesh.V, reversed), 2);
  EXPECT_THROW(faces_turned_over(mesh.V, mesh.F, mesh.V, mesh.F.topRows(3)), std::invalid_argument);
  const DistanceQuery target(mesh.V, mesh.F);
  EdgeFlipOptions bad;
  bad.min_quality = 2;
  EXPECT_THROW(flip_edges_toward(mesh.V, mesh.F, target, bad), std::invalid_argument);
  bad = {};
  bad.max_passes = 0;
  EXPECT_THROW(flip_edges_toward(mesh.V, mesh.F, target, bad), std::invalid_argument);
  const Vertices wrong(2, 3);
  EXPECT_THROW(flip_edges_toward(mesh.V, mesh.F, target, {}, &wrong), std::invalid_argument);
  EXPECT_THROW(flip_edges_toward(mesh.V, Faces(0, 3), target), std::invalid_argument);
}

}  // namespace
}  // namespace vertexflow
