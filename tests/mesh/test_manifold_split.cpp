// The manifold split (manifold_split.h): non-manifold vertices and edges cut apart, faces
// oriented per component, the way back to the input's vertices.
#include "shapes.h"
#include "test_support.h"

#include "vertexflow/io.h"
#include "vertexflow/manifold_split.h"
#include "vertexflow/topology.h"

#include <gtest/gtest.h>

#include <cmath>

namespace vertexflow {
namespace {

// The split's topology is manifold and oriented, its faces are the input's re-indexed (up to
// the recorded reversals), and each copy sits where its source vertex is.
void expect_valid_split(const Mesh& mesh, const ManifoldSplit& split) {
  const Topology topology = build_topology(split.F, split.V.rows());
  EXPECT_TRUE(topology.is_manifold()) << describe_non_manifold(topology);
  EXPECT_TRUE(topology.is_oriented);
  ASSERT_EQ(split.F.rows(), mesh.F.rows());
  for (Index f = 0; f < mesh.num_faces(); ++f) {
    Eigen::RowVector3i corners;
    for (int k = 0; k < 3; ++k)
      corners[k] = static_cast<int>(split.source_vertex[static_cast<std::size_t>(split.F(f, k))]);
    if (split.reversed_face[static_cast<std::size_t>(f)]) std::swap(corners[1], corners[2]);
    ASSERT_EQ(corners, mesh.F.row(f).cast<int>()) << "face " << f;
  }
  for (Index s = 0; s < split.V.rows(); ++s)
    ASSERT_EQ(split.V.row(s), mesh.V.row(split.source_vertex[static_cast<std::size_t>(s)]));
  for (Index v = 0; v < mesh.num_vertices(); ++v) {
    const Index copies =
        split.first_copy[static_cast<std::size_t>(v) + 1] - split.first_copy[static_cast<std::size_t>(v)];
    EXPECT_EQ(split.held[static_cast<std::size_t>(v)], copies > 1 ? 1 : 0) << v;
  }
}

ManifoldSplit split_of(const Mesh& mesh) {
  return split_non_manifold(mesh.V, mesh.F, build_topology(mesh.F, mesh.num_vertices()));
}

TEST(ManifoldSplit, AManifoldOrientedMeshIsUnchanged) {
  const Mesh torus = test::torus(3, 1, 24, 12);
  const ManifoldSplit split = split_of(torus);
  EXPECT_TRUE(split.unchanged());
  EXPECT_EQ(split.V, torus.V);
  EXPECT_EQ(split.F, torus.F);
}

TEST(ManifoldSplit, ABowtieVertexBecomesTwoHeldCopies) {
  const Mesh bowtie = test::bowtie();
  const ManifoldSplit split = split_of(bowtie);
  expect_valid_split(bowtie, split);
  EXPECT_EQ(split.held_vertices, 1);
  EXPECT_EQ(split.V.rows(), bowtie.num_vertices() + 1);
  EXPECT_TRUE(split.held[0]);
}

TEST(ManifoldSplit, AFinEdgeIsCut) {
  // Three triangles on the edge (0, 1): a T-junction of sheets, as in CAD exports.
  Mesh fin;
  fin.V = (Vertices(5, 3) << 0, 0, 0, 1, 0, 0, 0.5, 1, 0, 0.5, -1, 0, 0.5, 0, 1).finished();
  fin.F = (Faces(3, 3) << 0, 1, 2, 1, 0, 3, 0, 1, 4).finished();
  const ManifoldSplit split = split_of(fin);
  expect_valid_split(fin, split);
  EXPECT_EQ(split.cut_non_manifold_edges, 1);
  EXPECT_TRUE(split.held[0] && split.held[1]);
  EXPECT_FALSE(split.held[2] || split.held[3] || split.held[4]);
  EXPECT_EQ(split.V.rows(), 5 + 2 * 2);  // each end of the edge in three fans
}

TEST(ManifoldSplit, FacesAgainstTheirComponentAreReversed) {
  Mesh sphere = test::icosphere(1.0, 2);
  const Index reversed[] = {3, 17, 40, 41, 100, 250};
  for (const Index f : reversed) std::swap(sphere.F(f, 1), sphere.F(f, 2));
  ASSERT_FALSE(build_topology(sphere.F, sphere.num_vertices()).is_oriented);
  const ManifoldSplit split = split_of(sphere);
  expect_valid_split(sphere, split);
  EXPECT_EQ(split.reversed_faces, 6);  // the minority, whatever face the walk starts from
  for (const Index f : reversed) EXPECT_TRUE(split.reversed_face[static_cast<std::size_t>(f)]) << f;
  EXPECT_EQ(split.held_vertices, 0);
  EXPECT_EQ(split.cut_orientation_edges, 0);
  EXPECT_GT(signed_volume(split.V, split.F), 0);  // outward, as most faces were
}

TEST(ManifoldSplit, AMoebiusStripIsCutWhereNoOrientationAgrees) {
  const int n = 30;
  Mesh strip;
  strip.V.resize(2 * n, 3);
  for (int i = 0; i < n; ++i) {
    const double u = 2 * M_PI * i / n;
    for (int s = 0; s < 2; ++s) {
      const double w = s == 0 ? -0.3 : 0.3;
      strip.V.row(2 * i + s) << (1 + w * std::cos(u / 2)) * std::cos(u), (1 + w * std::cos(u / 2)) * std::sin(u),
          w * std::sin(u / 2);
    }
  }
  strip.F.resize(2 * n, 3);
  for (int i = 0; i < n; ++i) {
    const bool last = i == n - 1;  // the half twist joins side s to side 1 - s
    const Index a = 2 * i, b = 2 * i + 1, c = last ? 1 : 2 * i + 2, d = last ? 0 : 2 * i + 3;
    strip.F.row(2 * i) << a, c, b;
    strip.F.row(2 * i + 1) << b, c, d;
  }
  const Topology topology = build_topology(strip.F, strip.num_vertices());
  ASSERT_TRUE(topology.is_manifold());
  ASSERT_FALSE(topology.is_oriented);
  const ManifoldSplit split = split_of(strip);
  expect_valid_split(strip, split);
  EXPECT_EQ(split.cut_orientation_edges, 1);
}

// Vertex-clustered scans (how the Stanford low-resolution scans were made) have non-manifold
// edges and vertices; every one of them is held, and nothing else is.
TEST(ManifoldSplit, VertexClusteredBunnyHoldsExactlyItsNonManifoldVertices) {
  const Mesh bunny = read_mesh(test::data_path("bunny.off"));
  const Mesh coarse = test::vertex_clustered(bunny, 0.02 * bounding_box(bunny.V).diagonal());
  const Topology topology = build_topology(coarse.F, coarse.num_vertices());
  ASSERT_GT(topology.non_manifold_edges.size(), 10u);
  const ManifoldSplit split = split_non_manifold(coarse.V, coarse.F, topology);
  expect_valid_split(coarse, split);
  std::vector<char> non_manifold(static_cast<std::size_t>(coarse.num_vertices()), 0);
  for (const Index v : topology.non_manifold_vertices) non_manifold[static_cast<std::size_t>(v)] = 1;
  for (const Index e : topology.non_manifold_edges)
    non_manifold[static_cast<std::size_t>(topology.edges(e, 0))] =
        non_manifold[static_cast<std::size_t>(topology.edges(e, 1))] = 1;
  Index held_not_non_manifold = 0;
  for (Index v = 0; v < coarse.num_vertices(); ++v) {
    if (non_manifold[static_cast<std::size_t>(v)]) {
      EXPECT_TRUE(split.held[static_cast<std::size_t>(v)]) << v;
    }
    held_not_non_manifold += split.held[static_cast<std::size_t>(v)] && !non_manifold[static_cast<std::size_t>(v)];
  }
  // Cut apart only by an orientation conflict (measured: none).
  EXPECT_EQ(held_not_non_manifold, 0);
}

TEST(ManifoldSplit, RefusesATopologyOfAnotherMesh) {
  const Mesh a = test::icosphere(1.0, 0), b = test::icosphere(1.0, 1);
  EXPECT_THROW(split_non_manifold(a.V, a.F, build_topology(b.F, b.num_vertices())), std::invalid_argument);
}

}  // namespace
}  // namespace vertexflow
