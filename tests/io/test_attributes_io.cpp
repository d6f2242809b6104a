// Attributes through the readers and writers (attributes.h, io.h): a read followed by a write
// reproduces every channel's name, components, type, order and values; OBJ's texture
// coordinates, normals, materials, groups and smoothing groups; the face list as the file has
// it (ReadOptions::keep_face_list).
#include "attribute_checks.h"
#include "test_support.h"

#include "vertexflow/io.h"

#include <gtest/gtest.h>

#include <fstream>
#include <string>

namespace vertexflow {
namespace {

void write_bytes(const std::filesystem::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

TEST(AttributesIo, SpotObjKeepsItsTextureCoordinatesThroughObjAndPly) {
  const Mesh spot = read_mesh(test::data_path("spot.obj"));
  const CornerChannel* uv = spot.attributes.find_corner("uv");
  ASSERT_NE(uv, nullptr);
  EXPECT_EQ(uv->channel.rows(), 3225);  // spot.obj's vt lines
  EXPECT_EQ(uv->channel.role, AttributeRole::TexCoord);
  EXPECT_GE(uv->corners.minCoeff(), 0);  // every corner has one: f v/t
  // The first face is "f 739/1 735/2 736/3".
  EXPECT_EQ(spot.F.row(0), Eigen::RowVector3i(738, 734, 735));
  EXPECT_EQ(uv->corners.row(0), (Eigen::Matrix<std::int32_t, 1, 3>(0, 1, 2)));
  test::ScratchDir dir("attributes-spot");
  write_mesh(dir.file("spot.obj"), spot);
  test::expect_same_attributes(spot, read_mesh(dir.file("spot.obj")));
  EXPECT_TRUE(attributes_not_written(spot, MeshFormat::Obj).empty());
  // PLY holds per-corner texture coordinates as MeshLab's face `texcoord` lists: the values at
  // every corner survive (the table becomes one row per corner).
  write_mesh(dir.file("spot.ply"), spot);
  const Mesh ply = read_mesh(dir.file("spot.ply"));
  const CornerChannel* texcoord = ply.attributes.find_corner("texcoord");
  ASSERT_NE(texcoord, nullptr);
  for (Index f = 0; f < spot.num_faces(); ++f)
    for (int k = 0; k < 3; ++k)
      ASSERT_EQ(texcoord->channel.values.row(texcoord->corners(f, k)), uv->channel.values.row(uv->corners(f, k)));
  // STL holds none of it, and says so.
  EXPECT_EQ(attributes_not_written(spot, MeshFormat::Stl), std::vector<std::string>{"corner uv"});
}

TEST(AttributesIo, SuzanneObjKeepsNormalsMaterialObjectAndLibrary) {
  const Mesh suzanne = read_mesh(test::data_path("suzanne.obj"));
  const CornerChannel* normal = suzanne.attributes.find_corner("normal");
  ASSERT_NE(normal, nullptr);
  EXPECT_EQ(normal->channel.rows(), 499);  // suzanne.obj's vn lines
  EXPECT_EQ(suzanne.attributes.materials, std::vector<std::string>{"None"});
  EXPECT_EQ(suzanne.attributes.objects, std::vector<std::string>{"Suzanne"});
  EXPECT_EQ(suzanne.attributes.material_libraries, std::vector<std::string>{"affe.mtl"});
  test::ScratchDir dir("attributes-suzanne");
  write_mesh(dir.file("s.obj"), suzanne);
  test::expect_same_attributes(suzanne, read_mesh(dir.file("s.obj")));
}

// An OBJ with every statement a face carries, polygons and a mix of corner forms.
const char* kObj =
    "mtllib a.mtl b.mtl\n"
    "o first\n"
    "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\n"
    "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvt 0.5 0.5\n"
    "vn 0 0 1\nvn 0 1 0\n"
    "g left side\nusemtl red\ns 1\n"
    "f 1/1/1 2/2/1 3/3/1 4/4/1\n"
    "usemtl blue\ns off\n"
    "f 1//2 2//2 5//2\n"
    "g right\nusemtl red\n"
    "f -4/-2 -3/-1 -1/-5\n";

TEST(AttributesIo, ObjStatementsRoundTripAndFollowTheTriangulation) {
  test::ScratchDir dir("attributes-obj");
  write_bytes(dir.file("in.obj"), kObj);
  const Mesh mesh = read_mesh(dir.file("in.obj"));
  ASSERT_EQ(mesh.num_faces(), 4);  // the quad became two triangles
  EXPECT_EQ(mesh.attributes.materials, (std::vector<std::string>{"red", "blue"}));
  EXPECT_EQ(mesh.attributes.groups, (std::vector<std::string>{"left side", "right"}));
  EXPECT_EQ(mesh.attributes.material_libraries, std::vector<std::string>{"a.mtl b.mtl"});
  const AttributeChannel* material = mesh.attributes.find_face("material");
  const AttributeChannel* group = mesh.attributes.find_face("group");
  const AttributeChannel* smoothing = mesh.attributes.find_face("smoothing");
  ASSERT_TRUE(material && group && smoothing);
  EXPECT_EQ(material->values.col(0).transpose(), Eigen::RowVector4d(0, 0, 1, 0));
  EXPECT_EQ(group->values.col(0).transpose(), Eigen::RowVector4d(0, 0, 0, 1));
  EXPECT_EQ(smoothing->values.col(0).transpose(), Eigen::RowVector4d(1, 1, 0, 0));
  const CornerChannel* uv = mesh.attributes.find_corner("uv");
  ASSERT_NE(uv, nullptr);
  // Each triangle corner of the quad has the texture coordinate of its polygon corner.
  for (Index f = 0; f < 2; ++f)
    for (int k = 0; k < 3; ++k) EXPECT_EQ(uv->corners(f, k), mesh.F(f, k)) << f;  // vt i at v i
  EXPECT_EQ(uv->corners.row(2), (Eigen::Matrix<std::int32_t, 1, 3>(-1, -1, -1)));
  EXPECT_EQ(uv->corners.row(3), (Eigen::Matrix<std::int32_t, 1, 3>(3, 4, 0)));  // negative indices
  write_mesh(dir.file("out.obj"), mesh);
  test::expect_same_attributes(mesh, read_mesh(dir.file("out.obj")));
  // A face index past the table is an error naming the file.
  write_bytes(dir.file("bad.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/2 3/1\n");
  try {
    read_mesh(dir.file("bad.obj"));
    FAIL();
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("texture coordinate 2, but the file has 1"), std::string::npos) << e.what();
  }
}

// A PLY with a property of every type on the vertices and the faces, grouped and single.
std::string every_type_ply(const char* format) {
  return std::string("ply\nformat ") + format +
         " 1.0\nelement vertex 4\nproperty double x\nproperty double y\nproperty double z\n"
         "property uchar red\nproperty uchar green\nproperty uchar blue\nproperty uchar alpha\n"
         "property float nx\nproperty float ny\nproperty float nz\nproperty float s\nproperty float t\n"
         "property char c8\nproperty short s16\nproperty ushort u16\nproperty int i32\nproperty uint u32\n"
         "property double quality\n"
         "element face 2\nproperty list uchar int vertex_indices\nproperty int material\nproperty float area\n"
         "property uchar red\nproperty uchar green\nproperty uchar blue\n"
         "property list uchar float texcoord\nend_header\n";
}

const char* kEveryTypeBody =
    "0 0 0 255 0 7 128 0 0 1 0.1 0.9 -128 -32768 65535 -2147483648 4294967295 0.30000000000000004\n"
    "1 0 0 0 255 0 255 0 0 1 0.25 0.5 127 32767 0 2147483647 0 -1e-300\n"
    "1 1 0 1 2 3 4 0 0.6 0.8 1 1 0 0 1 2 3 4\n"
    "0 1 0 9 8 7 6 0 0 -1 0 1 -1 -2 3 -4 5 6.5\n"
    "3 0 1 2 7 0.5 10 20 30 6 0 0 1 0 1 1\n"
    "3 0 2 3 -3 0.125 40 50 60 6 0 0 1 1 0 1\n";

TEST(AttributesIo, PlyPropertiesOfEveryTypeRoundTripInEveryEncoding) {
  test::ScratchDir dir("attributes-ply");
  write_bytes(dir.file("in.ply"), every_type_ply("ascii") + kEveryTypeBody);
  const Mesh mesh = read_mesh(dir.file("in.ply"));
  const MeshAttributes& a = mesh.attributes;
  ASSERT_EQ(a.vertex.size(), 9u);  // color(4) normal(3) uv(2) c8 s16 u16 i32 u32 quality
  EXPECT_EQ(a.vertex[0].name, "color");
  EXPECT_EQ(a.vertex[0].width(), 4);
  EXPECT_EQ(a.vertex[1].role, AttributeRole::Normal);
  EXPECT_EQ(a.vertex[2].role, AttributeRole::TexCoord);
  EXPECT_EQ(a.vertex[2].components, (std::vector<std::string>{"s", "t"}));
  EXPECT_EQ(a.vertex[3].type, ScalarType::Int8);
  EXPECT_EQ(a.vertex[3].role, AttributeRole::Label);
  EXPECT_EQ(a.vertex[7].values(0, 0), 4294967295.0);
  EXPECT_EQ(a.vertex[6].values(0, 0), -2147483648.0);
  EXPECT_EQ(a.vertex[8].values(0, 0), 0.30000000000000004);
  EXPECT_EQ(a.vertex[2].values(0, 0), static_cast<double>(0.1f));  // a float property holds a float
  ASSERT_EQ(a.face.size(), 3u);                                    // material, area, color
  EXPECT_EQ(a.face[0].values(1, 0), -3);
  EXPECT_EQ(a.face[2].role, AttributeRole::Color);
  const CornerChannel* texcoord = a.find_corner("texcoord");
  ASSERT_NE(texcoord, nullptr);
  EXPECT_EQ(texcoord->channel.values.row(texcoord->corners(1, 2)), Eigen::RowVector2d(0, 1));
  for (const PlyEncoding encoding :
       {PlyEncoding::Ascii, PlyEncoding::BinaryLittleEndian, PlyEncoding::BinaryBigEndian}) {
    WriteOptions options;
    options.ply_encoding = encoding;
    const auto path = dir.file("out" + std::to_string(static_cast<int>(encoding)) + ".ply");
    write_mesh(path, mesh, options);
    const Mesh back = read_mesh(path);
    SCOPED_TRACE(static_cast<int>(encoding));
    test::expect_same_attributes(mesh, back);
  }
  // An integer property's ASCII value must fit its type.
  std::string bad = every_type_ply("ascii") + kEveryTypeBody;
  bad.replace(bad.find("-128 -32768"), 4, "-129");
  write_bytes(dir.file("bad.ply"), bad);
  EXPECT_THROW(read_mesh(dir.file("bad.ply")), IoError);
}

TEST(AttributesIo, KeepFaceListKeepsEveryFaceAndVertexInOrder) {
  test::ScratchDir dir("attributes-faces");
  // Face 1 repeats face 0 reversed, face 2 has zero area (collinear), face 3 a repeated vertex,
  // vertex 6 has no face.
  write_bytes(dir.file("in.obj"),
              "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nv 3 0 0\nv 0 0 1\nv 9 9 9\n"
              "f 1 2 3\nf 3 2 1\nf 2 4 5\nf 1 1 6\nf 1 2 6\n");
  ReadOptions keep;
  keep.keep_face_list = true;
  ReadReport report;
  const Mesh kept = read_mesh(dir.file("in.obj"), &report, keep);
  EXPECT_EQ(kept.num_faces(), 5);
  EXPECT_EQ(kept.num_vertices(), 7);
  EXPECT_EQ(kept.F.row(3), Eigen::RowVector3i(0, 0, 5));
  EXPECT_EQ(report.degenerate_faces_kept, 2);
  EXPECT_EQ(report.duplicate_faces_kept, 1);
  EXPECT_EQ(report.unreferenced_vertices_kept, 1);
  // The default read still cleans.
  const Mesh clean = read_mesh(dir.file("in.obj"));
  EXPECT_EQ(clean.num_faces(), 2);
}

}  // namespace
}  // namespace vertexflow
