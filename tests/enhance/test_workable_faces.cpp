// The faces the enhance engine works on (src/enhance/workable_faces.h): repeated faces found by
// the topology's proof where every edge has at most two faces, and by the sort otherwise, with
// the same answer either way.
#include "shapes.h"

#include "enhance/workable_faces.h"
#include "vertexflow/topology.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <initializer_list>
#include <optional>
#include <vector>

namespace vertexflow {
namespace {

// `mesh` with the faces `extra` appended over three new vertices (a triangle off the surface).
Mesh with_faces_on_new_vertices(const Mesh& mesh, const std::vector<std::array<Index, 3>>& extra) {
  Mesh out = mesh;
  const Index n = mesh.num_vertices();
  out.V.conservativeResize(n + 3, 3);
  out.V.row(n) = Eigen::RowVector3d(3, 0, 0);
  out.V.row(n + 1) = Eigen::RowVector3d(3, 1, 0);
  out.V.row(n + 2) = Eigen::RowVector3d(3, 0, 1);
  out.F.conservativeResize(mesh.F.rows() + static_cast<Eigen::Index>(extra.size()), 3);
  for (std::size_t k = 0; k < extra.size(); ++k)
    out.F.row(mesh.F.rows() + static_cast<Eigen::Index>(k)) << n + extra[k][0], n + extra[k][1], n + extra[k][2];
  return out;
}

// Faces 0 .. count - 1 but `left_out`.
std::vector<Index> faces_but(Index count, std::initializer_list<Index> left_out) {
  std::vector<Index> faces;
  for (Index f = 0; f < count; ++f)
    if (std::find(left_out.begin(), left_out.end(), f) == left_out.end()) faces.push_back(f);
  return faces;
}

TEST(WorkableFaces, RepeatsAreFoundWithOrWithoutTheTopologysProof) {
  const Mesh sphere = test::icosphere(1.0, 2);
  const auto m = static_cast<Index>(sphere.F.rows());
  {
    // Nothing to hold: every face, and the topology of all of them for the run.
    std::optional<Topology> topology;
    EXPECT_EQ(enhance_detail::workable_faces(sphere, &topology), faces_but(m, {}));
    ASSERT_TRUE(topology.has_value());
    EXPECT_EQ(topology->num_faces, m);
  }
  // A pillow: a triangle and its reverse, every edge with two faces (the proof's case: the later
  // face is adjacent to the earlier across all three edges); a triangle repeated twice beside it,
  // edges of three faces (the sort's case); a sphere's face repeated.
  Mesh repeated_sphere_face = sphere;
  repeated_sphere_face.F.conservativeResize(m + 1, 3);
  repeated_sphere_face.F.row(m) = sphere.F.row(5);
  const std::pair<Mesh, std::vector<Index>> cases[] = {
      {with_faces_on_new_vertices(sphere, {{0, 1, 2}, {0, 2, 1}}), faces_but(m + 2, {m + 1})},
      {with_faces_on_new_vertices(sphere, {{0, 1, 2}, {1, 2, 0}, {0, 2, 1}}), faces_but(m + 3, {m + 1, m + 2})},
      {repeated_sphere_face, faces_but(m + 1, {m})},
  };
  for (const auto& [mesh, expected] : cases) {
    std::optional<Topology> topology;
    EXPECT_EQ(enhance_detail::workable_faces(mesh, &topology), expected);
    EXPECT_EQ(enhance_detail::workable_faces(mesh), expected);  // the sort alone
    EXPECT_TRUE(topology.has_value());                          // no face was degenerate
  }
  // A face with a repeated vertex: no topology is built (build_topology would refuse it).
  Mesh degenerate = sphere;
  degenerate.F(3, 2) = degenerate.F(3, 1);
  std::optional<Topology> topology;
  EXPECT_EQ(enhance_detail::workable_faces(degenerate, &topology), faces_but(m, {3}));
  EXPECT_FALSE(topology.has_value());
}

}  // namespace
}  // namespace vertexflow
