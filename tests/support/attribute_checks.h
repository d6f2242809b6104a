// Comparisons of meshes with attributes (attributes.h) for the round-trip tests of every format.
#pragma once

#include "vertexflow/mesh.h"

#include <gtest/gtest.h>

namespace vertexflow::test {

/// Name, component names, type, role and every value, exactly (doubles hold every type's values).
inline void expect_same_channel(const AttributeChannel& a, const AttributeChannel& b) {
  EXPECT_EQ(a.name, b.name);
  EXPECT_EQ(a.components, b.components) << a.name;
  EXPECT_EQ(a.type, b.type) << a.name;
  EXPECT_EQ(a.role, b.role) << a.name;
  ASSERT_EQ(a.values.rows(), b.values.rows()) << a.name;
  ASSERT_EQ(a.values.cols(), b.values.cols()) << a.name;
  EXPECT_TRUE(a.values == b.values) << a.name;
}

/// V, F, every vertex, corner and face channel in order, and the name tables (not the glTF
/// document itself).
inline void expect_same_attributes(const Mesh& a, const Mesh& b) {
  EXPECT_TRUE(a.V == b.V);
  EXPECT_TRUE(a.F == b.F);
  const MeshAttributes &x = a.attributes, &y = b.attributes;
  ASSERT_EQ(x.vertex.size(), y.vertex.size());
  for (std::size_t i = 0; i < x.vertex.size(); ++i) expect_same_channel(x.vertex[i], y.vertex[i]);
  ASSERT_EQ(x.face.size(), y.face.size());
  for (std::size_t i = 0; i < x.face.size(); ++i) expect_same_channel(x.face[i], y.face[i]);
  ASSERT_EQ(x.corner.size(), y.corner.size());
  for (std::size_t i = 0; i < x.corner.size(); ++i) {
    expect_same_channel(x.corner[i].channel, y.corner[i].channel);
    EXPECT_TRUE(x.corner[i].corners == y.corner[i].corners) << x.corner[i].channel.name;
  }
  EXPECT_EQ(x.materials, y.materials);
  EXPECT_EQ(x.groups, y.groups);
  EXPECT_EQ(x.objects, y.objects);
  EXPECT_EQ(x.material_libraries, y.material_libraries);
}

}  // namespace vertexflow::test
