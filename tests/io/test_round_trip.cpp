// read -> write -> read gives the same mesh, exactly for formats that store doubles in text
// or binary64, and to float32 precision for formats that store float32.
#include "test_support.h"

#include "vertexflow/io.h"

#include <gtest/gtest.h>

#include <map>

namespace vertexflow {
namespace {

struct Case {
  const char* name;
  const char* extension;
  WriteOptions options;
  bool exact;           // positions stored losslessly
  bool keeps_vertices;  // STL does not store shared vertices: compare after welding
  bool keeps_properties;
  friend void PrintTo(const Case& c, std::ostream* os) { *os << c.name; }
};

WriteOptions with(void (*edit)(WriteOptions&)) {
  WriteOptions o;
  edit(o);
  return o;
}

const Case kCases[] = {
    {"obj", ".obj", {}, true, true, false},
    {"obj_gz", ".obj.gz", {}, true, true, false},
    {"off_ascii", ".off", {}, true, true, false},
    {"off_binary", ".off", with([](WriteOptions& o) { o.off_binary = true; }), false, true, false},
    {"ply_binary_le", ".ply", {}, true, true, true},
    {"ply_binary_be", ".ply", with([](WriteOptions& o) { o.ply_encoding = PlyEncoding::BinaryBigEndian; }), true, true,
     true},
    {"ply_ascii", ".ply", with([](WriteOptions& o) { o.ply_encoding = PlyEncoding::Ascii; }), true, true, true},
    {"ply_float", ".ply", with([](WriteOptions& o) { o.ply_double_precision = false; }), false, true, true},
    {"ply_gz", ".ply.gz", {}, true, true, true},
    {"stl_binary", ".stl", {}, false, false, false},
    {"stl_ascii", ".stl", with([](WriteOptions& o) { o.stl_binary = false; }), true, false, false},
};

// A mesh with awkward coordinates (not representable in few digits), colours and a property.
Mesh test_mesh() {
  Mesh mesh = read_mesh(test::data_path("bunny_uniform.off"));
  mesh.V.col(0) *= 1.0 / 3.0;  // full-precision doubles
  mesh.V.col(1).array() += 1e-7;
  Colors colors(mesh.num_vertices(), 3);
  for (Index v = 0; v < mesh.num_vertices(); ++v) colors.row(v) << v % 256, (7 * v) % 256, 255;
  mesh.set_vertex_colors(colors);
  mesh.set_vertex_property("k1", mesh.V.col(0) * 12.5);
  return mesh;
}

class RoundTrip : public ::testing::TestWithParam<Case> {};

TEST_P(RoundTrip, ReadWriteReadIsIdentity) {
  const Case& c = GetParam();
  const Mesh original = test_mesh();
  test::ScratchDir dir("roundtrip");
  const auto path = dir.file(std::string("mesh") + c.extension);
  write_mesh(path, original, c.options);
  ReadReport report;
  const Mesh back = read_mesh(path, &report);
  EXPECT_EQ(report.gzip, is_gzip_path(path));
  ASSERT_EQ(back.num_faces(), original.num_faces());
  ASSERT_EQ(back.num_vertices(), original.num_vertices());

  const double tolerance = c.exact ? 0.0 : 1e-7 * original.V.cwiseAbs().maxCoeff();
  if (c.keeps_vertices) {
    EXPECT_EQ(back.F, original.F);
    EXPECT_LE((back.V - original.V).cwiseAbs().maxCoeff(), tolerance);
  } else {
    // Welded STL: every face's corners are the same points, in the same order.
    for (Index f = 0; f < original.num_faces(); ++f) {
      for (int k = 0; k < 3; ++k) {
        ASSERT_LE((back.V.row(back.F(f, k)) - original.V.row(original.F(f, k))).cwiseAbs().maxCoeff(), tolerance)
            << "face " << f;
      }
    }
  }
  if (c.keeps_properties) {
    ASSERT_EQ(back.vertex_colors().rows(), original.vertex_colors().rows());
    EXPECT_EQ(back.vertex_colors(), original.vertex_colors());
    const AttributeChannel* k1 = back.find_vertex_property("k1");
    ASSERT_NE(k1, nullptr);
    EXPECT_EQ(k1->values, original.find_vertex_property("k1")->values);
  }
  // Nothing but the output is left in the directory (no temporary files).
  int files = 0;
  for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator(dir.path())) ++files;
  EXPECT_EQ(files, 1);
}

INSTANTIATE_TEST_SUITE_P(Formats, RoundTrip, ::testing::ValuesIn(kCases),
                         [](const auto& param_info) { return std::string(param_info.param.name); });

TEST(RoundTrip, PolygonMeshTriangulatedOnceStaysTheSame) {
  // suzanne.obj has quads: after the first read it is a triangle mesh, and a second round trip
  // through every format changes nothing.
  const Mesh first = read_mesh(test::data_path("suzanne.obj"));
  test::ScratchDir dir("polygons");
  for (const char* ext : {".obj", ".off", ".ply"}) {
    const auto path = dir.file(std::string("suzanne") + ext);
    write_mesh(path, first);
    ReadReport report;
    const Mesh second = read_mesh(path, &report);
    EXPECT_EQ(second.F, first.F) << ext;
    EXPECT_EQ(second.V, first.V) << ext;
    EXPECT_TRUE(report.warnings().empty()) << ext;
  }
}

}  // namespace
}  // namespace vertexflow
