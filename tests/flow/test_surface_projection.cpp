// Feature detection of the flow's projection (src/flow/surface_projection.h): which sharp edges
// are creases, which vertices are corners.
#include "shapes.h"
#include "test_support.h"
#include "vertexflow/features.h"

#include "vertexflow/io.h"
#include "vertexflow/topology.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace vertexflow {
namespace {

// An n x n grid of unit squares in the xy-plane (x, y in [-n/2, n/2]) folded along y = 0:
// z = slope(x) |y|. The fold's dihedral angle is 2 atan(slope(x)).
template <class Slope>
Mesh folded_plate(int n, Slope&& slope) {
  Mesh mesh;
  mesh.V.resize((n + 1) * (n + 1), 3);
  for (int i = 0; i <= n; ++i) {
    for (int j = 0; j <= n; ++j) {
      const double x = i - n / 2.0, y = j - n / 2.0;
      mesh.V.row(i * (n + 1) + j) << x, y, slope(x) * std::abs(y);
    }
  }
  mesh.F.resize(2 * n * n, 3);
  Index f = 0;
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      const Index a = i * (n + 1) + j, b = a + n + 1, c = b + 1, d = a + 1;
      mesh.F.row(f++) << a, b, c;
      mesh.F.row(f++) << a, c, d;
    }
  }
  return mesh;
}

SurfaceFeatures features_of(const Mesh& mesh, double angle = 40.0) {
  return detect_features(mesh.V, mesh.F, build_topology(mesh.F, mesh.num_vertices()), angle);
}

Index count(const SurfaceFeatures& features, SurfaceFeatures::Kind kind) {
  return static_cast<Index>(std::count(features.vertex_kind.begin(), features.vertex_kind.end(), kind));
}

Index sharp_edges(const SurfaceFeatures& features) {
  return static_cast<Index>(std::count(features.sharp_edge.begin(), features.sharp_edge.end(), 1));
}

TEST(FeatureDetection, AFoldAcrossThePlateIsACrease) {
  // 2 atan(1.5) = 113 degrees all along y = 0, from boundary to boundary: two patches.
  const Mesh mesh = folded_plate(12, [](double) { return 1.5; });
  const SurfaceFeatures features = features_of(mesh);
  EXPECT_EQ(sharp_edges(features), 12);
  EXPECT_EQ(count(features, SurfaceFeatures::Kind::Crease), 11);  // the interior fold vertices
  EXPECT_EQ(*std::max_element(features.face_patch.begin(), features.face_patch.end()), 1);
}

TEST(FeatureDetection, AFoldThatFadesOutInsideThePlateIsNotACrease) {
  // The same fold, flattening out from x = -2 to x = 2: its sharp edges (dihedral above 40
  // degrees for x below about 1) end inside the plate, with one patch on both sides. Such a
  // chain (an under-sampled ridge or the noise of a scan) is not a crease, and its inner end is
  // not a corner the flow would have to hold.
  const Mesh mesh = folded_plate(12, [](double x) { return std::clamp(1.5 * (2.0 - x) / 4.0, 0.0, 1.5); });
  const SurfaceFeatures features = features_of(mesh);
  EXPECT_EQ(sharp_edges(features), 0);
  EXPECT_EQ(count(features, SurfaceFeatures::Kind::Smooth), mesh.num_vertices());
  EXPECT_EQ(*std::max_element(features.face_patch.begin(), features.face_patch.end()), 0);
}

TEST(FeatureDetection, WithoutSharpEdgesEachConnectedPieceIsOnePatch) {
  // A smooth sphere is one patch; two spheres side by side are two, numbered by their lowest
  // face (the flood fill's order), whatever their vertices' order.
  const Mesh sphere = test::icosphere(1.0, 2);
  const SurfaceFeatures one = features_of(sphere);
  EXPECT_EQ(sharp_edges(one), 0);
  EXPECT_TRUE(std::all_of(one.face_patch.begin(), one.face_patch.end(), [](Index p) { return p == 0; }));
  Mesh two;
  two.V.resize(2 * sphere.num_vertices(), 3);
  two.V << sphere.V, sphere.V.rowwise() + Eigen::RowVector3d(3, 0, 0);
  two.F.resize(2 * sphere.num_faces(), 3);
  two.F << sphere.F.array() + sphere.num_vertices(), sphere.F;  // the second sphere's faces first
  const SurfaceFeatures pieces = features_of(two);
  EXPECT_EQ(sharp_edges(pieces), 0);
  for (Index f = 0; f < two.num_faces(); ++f)
    ASSERT_EQ(pieces.face_patch[static_cast<std::size_t>(f)], f < sphere.num_faces() ? 0 : 1) << "face " << f;
}

TEST(FeatureDetection, ScannedBunnyHasFewCornersAndCadPartsKeepTheirs) {
  // bunny_uniform is a smooth scan: at 40 degrees 268 of its edges are sharp, in open chains
  // whose ends made 132 vertices corners. Only the few closed loops of sharp edges remain.
  const SurfaceFeatures bunny = features_of(read_mesh(test::data_path("bunny_uniform.off")));
  EXPECT_LE(count(bunny, SurfaceFeatures::Kind::Corner), 20);
  EXPECT_LE(sharp_edges(bunny), 30);
  // fandisk's creases cut it into faces: (almost) all remain, with the corners where they meet.
  const SurfaceFeatures fandisk = features_of(read_mesh(test::data_path("fandisk.off")));
  EXPECT_GE(sharp_edges(fandisk), 600);
  EXPECT_GE(count(fandisk, SurfaceFeatures::Kind::Corner), 20);
  // The chamfered cube: every vertex is a corner of its 45-degree chamfers.
  const SurfaceFeatures cube = features_of(read_mesh(test::data_path("chamfer-cube.off")));
  EXPECT_EQ(count(cube, SurfaceFeatures::Kind::Corner), 24);
}

TEST(FeatureDetection, PatchesAreTheFloodFillsAcrossNonSharpEdgesInFaceOrder) {
  // The patches are found on all threads (concurrent_union_find.h); they must be the sets a flood
  // fill from each unlabelled face in order finds across the interior edges left non-sharp,
  // numbered in that order (an edge unmarked for ending inside one patch joins nothing new).
  // At 40 degrees fandisk has 12 patches, the chamfered cube 7 and the open perforated plate 21
  // (measured); the plate's faces also come shuffled, and each case runs on one thread and on
  // two.
  const Mesh plate = test::perforated_plate(2, 3, 0.3, false);
  for (const Mesh& mesh : {read_mesh(test::data_path("fandisk.off")), read_mesh(test::data_path("chamfer-cube.off")),
                           plate, test::renumbered(plate, 5, true).mesh}) {
    const Topology topology = build_topology(mesh.F, mesh.num_vertices());
    for (const int threads : {1, 2}) {
      tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
      const SurfaceFeatures features = detect_features(mesh.V, mesh.F, topology, 40.0);
      std::vector<Index> expected(static_cast<std::size_t>(mesh.num_faces()), -1);
      Index patches = 0;
      for (Index seed = 0; seed < mesh.num_faces(); ++seed) {
        if (expected[static_cast<std::size_t>(seed)] >= 0) continue;
        std::vector<Index> stack{seed};
        expected[static_cast<std::size_t>(seed)] = patches;
        while (!stack.empty()) {
          const Index f = stack.back();
          stack.pop_back();
          for (int k = 0; k < 3; ++k) {
            const Index g = topology.face_adjacency(f, k);
            if (g >= 0 && !features.sharp_edge[static_cast<std::size_t>(topology.face_edges(f, k))] &&
                expected[static_cast<std::size_t>(g)] < 0) {
              expected[static_cast<std::size_t>(g)] = patches;
              stack.push_back(g);
            }
          }
        }
        ++patches;
      }
      EXPECT_GE(patches, 7);  // the creases cut each of these into 7-21 patches
      EXPECT_EQ(features.face_patch, expected) << mesh.num_faces() << " faces, " << threads << " threads";
    }
  }
}

}  // namespace
}  // namespace vertexflow
