// Seams stored cut open (mesh/cut_seams.h): which copies weld, and which stay apart.
#include "shapes.h"
#include "test_support.h"

#include "mesh/cut_seams.h"

#include "vertexflow/io.h"
#include "vertexflow/topology.h"

#include <gtest/gtest.h>

namespace vertexflow {
namespace {

CutSeams seams_of(const Mesh& m) {
  return find_cut_seams(m.V, m.F, build_topology(m.F, m.num_vertices()));
}

// `mesh` with the vertices `cut` duplicated in the faces for which `side` holds: the copies are
// appended, at the same positions.
Mesh cut_open(const Mesh& mesh, const std::vector<Index>& cut, const std::function<bool(Index face)>& side) {
  Mesh out = mesh;
  std::vector<Index> copy(static_cast<std::size_t>(mesh.num_vertices()), -1);
  for (const Index v : cut) {
    copy[static_cast<std::size_t>(v)] = static_cast<Index>(out.V.rows());
    out.V.conservativeResize(out.V.rows() + 1, 3);
    out.V.row(out.V.rows() - 1) = mesh.V.row(v);
  }
  for (Index f = 0; f < mesh.num_faces(); ++f)
    if (side(f))
      for (int k = 0; k < 3; ++k)
        if (copy[static_cast<std::size_t>(mesh.F(f, k))] >= 0)
          out.F(f, k) = copy[static_cast<std::size_t>(mesh.F(f, k))];
  return out;
}

TEST(CutSeams, AClosedMeshHasNone) {
  const CutSeams seams = seams_of(test::icosphere(1.0, 2));
  EXPECT_TRUE(seams.empty());
  EXPECT_TRUE(seams.edges.empty());
}

// A closed cylinder of revolution cut along a generator (x > 0, y = 0): every copy welds back,
// each generator edge is a seam, and the welded faces are the uncut cylinder's.
TEST(CutSeams, ACylinderCutAlongAGeneratorWeldsBack) {
  const Mesh tube = test::cylinder(1.0, 2.0, 24, 10);
  const Topology topology = build_topology(tube.F, tube.num_vertices());
  ASSERT_FALSE(topology.boundary_loops.empty());  // the tube is open at its ends
  std::vector<Index> generator;
  for (Index v = 0; v < tube.num_vertices(); ++v)
    if (std::abs(tube.V(v, 1)) < 1e-12 && tube.V(v, 0) > 0) generator.push_back(v);
  ASSERT_EQ(generator.size(), 11u);
  // The faces on the y < 0 side of the generator take the copies.
  const Mesh cut = cut_open(tube, generator, [&](Index f) {
    double y = 0;
    for (int k = 0; k < 3; ++k) y += tube.V(tube.F(f, k), 1);
    return y < 0;
  });
  const CutSeams seams = seams_of(cut);
  EXPECT_EQ(seams.vertices_welded, 11);
  EXPECT_EQ(seams.edges.size(), 10u);
  for (Index v = 0; v < cut.num_vertices(); ++v) {
    const Index r = seams.representative[static_cast<std::size_t>(v)];
    EXPECT_LE(r, v);
    EXPECT_EQ(cut.V.row(r), cut.V.row(v));
  }
  Faces welded = cut.F;
  for (Index f = 0; f < welded.rows(); ++f)
    for (int k = 0; k < 3; ++k) welded(f, k) = seams.representative[static_cast<std::size_t>(cut.F(f, k))];
  EXPECT_EQ(welded, tube.F);
}

// Pieces that only touch at a point, and edges that three boundary edges join, stay apart.
TEST(CutSeams, PiecesTouchingAtAPointOrThreeEdgesAtOnceStayApart) {
  // Two triangles sharing a position at one corner only.
  Mesh touch;
  touch.V.resize(6, 3);
  touch.V << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 0, -1, 0, 0, 0, -1, 0;
  touch.F.resize(2, 3);
  touch.F << 0, 1, 2, 3, 4, 5;
  EXPECT_TRUE(seams_of(touch).empty());
  // Three fins on one edge: the positions (0,0,0)-(1,0,0) carry three boundary edges, two one
  // way and one back, so no pairing is unambiguous.
  Mesh fins;
  fins.V.resize(9, 3);
  fins.V << 0, 0, 0, 1, 0, 0, 0.5, 1, 0, 0, 0, 0, 1, 0, 0, 0.5, 0, 1, 0, 0, 0, 1, 0, 0, 0.5, -1, 0;
  fins.F.resize(3, 3);
  fins.F << 0, 1, 2, 4, 3, 5, 6, 7, 8;
  EXPECT_TRUE(seams_of(fins).empty());
  // The same two copies without the third fin do weld: a seam pair.
  Mesh pair = fins;
  pair.F.conservativeResize(2, 3);
  const CutSeams two = seams_of(pair);
  EXPECT_EQ(two.vertices_welded, 2);
  EXPECT_EQ(two.edges.size(), 1u);
}

// A seam that ends inside the surface (a slit): the vertex at its end is shared, the rest weld.
TEST(CutSeams, ASlitWeldsUpToItsEnd) {
  const Mesh grid = test::height_field(1.0, 8, [](double, double) { return 0.0; });
  // x = 0 from the rim (y = -1) to y = 0.25; the vertex at y = 0.5 stays shared: the slit's end.
  std::vector<Index> slit;
  for (Index v = 0; v < grid.num_vertices(); ++v)
    if (std::abs(grid.V(v, 0)) < 1e-12 && grid.V(v, 1) < 0.4) slit.push_back(v);
  ASSERT_GE(slit.size(), 3u);
  const Mesh cut = cut_open(grid, slit, [&](Index f) {
    double x = 0;
    for (int k = 0; k < 3; ++k) x += grid.V(grid.F(f, k), 0);
    return x > 0;
  });
  const CutSeams seams = seams_of(cut);
  EXPECT_EQ(seams.vertices_welded, static_cast<Index>(slit.size()));
  EXPECT_EQ(seams.edges.size(), slit.size());  // the slit's edges, the last one to its end
}

}  // namespace
}  // namespace vertexflow
