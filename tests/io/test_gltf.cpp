// glTF 2.0 reading and writing (io.h, src/io/gltf.h): the Khronos samples in data/gltf read,
// written and read again with every channel, face and image the same; vertices welded by
// position; skins kept and skin weights normalised after enhance moved the vertices; a mesh
// from OBJ written as a fresh document; compressed and non-triangle content reported.
#include "attribute_checks.h"
#include "gltf.h"
#include "test_support.h"

#include "vertexflow/enhance.h"
#include "vertexflow/io.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <sstream>
#include <string>
#include <tuple>

namespace vertexflow {
namespace {

ReadOptions keep_faces() {
  ReadOptions options;
  options.keep_face_list = true;
  return options;
}

const tinygltf::Model& model_of(const Mesh& mesh) {
  EXPECT_NE(mesh.attributes.gltf, nullptr);
  return mesh.attributes.gltf->model;
}

using Sample = std::tuple<std::string, std::string>;  // input under data/, output extension

class GltfRoundTrip : public ::testing::TestWithParam<Sample> {};

TEST_P(GltfRoundTrip, EveryChannelFaceAndImageComesBackTheSame) {
  const auto& [input, extension] = GetParam();
  const Mesh mesh = read_mesh(test::data_path(input), nullptr, keep_faces());
  ASSERT_FALSE(mesh.attributes.corner.empty());
  EXPECT_TRUE(attributes_not_written(mesh, MeshFormat::Gltf).empty());
  test::ScratchDir dir("gltf-round-trip");
  const auto out = dir.file("out" + extension);
  write_mesh(out, mesh);
  ReadReport report;
  const Mesh back = read_mesh(out, &report, keep_faces());
  EXPECT_EQ(report.binary, extension == ".glb");
  test::expect_same_attributes(mesh, back);
  const tinygltf::Model &a = model_of(mesh), &b = model_of(back);
  ASSERT_EQ(a.images.size(), b.images.size());
  for (std::size_t i = 0; i < a.images.size(); ++i) EXPECT_TRUE(a.images[i].image == b.images[i].image) << i;
  EXPECT_EQ(a.materials.size(), b.materials.size());
  EXPECT_EQ(a.textures.size(), b.textures.size());
  EXPECT_EQ(a.nodes.size(), b.nodes.size());
  EXPECT_EQ(a.skins.size(), b.skins.size());
  EXPECT_EQ(a.animations.size(), b.animations.size());
  EXPECT_EQ(a.meshes.size(), b.meshes.size());
  // A .gltf's buffers and images are files beside it, named after it.
  if (extension == ".gltf")
    for (const tinygltf::Buffer& buffer : b.buffers)
      if (buffer.uri.rfind("data:", 0) != 0) {
        EXPECT_TRUE(std::filesystem::exists(dir.file(buffer.uri))) << buffer.uri;
      }
}

INSTANTIATE_TEST_SUITE_P(Samples, GltfRoundTrip,
                         ::testing::Combine(::testing::Values("gltf/BoxTextured/BoxTextured.glb",
                                                              "gltf/BoxTextured/BoxTextured.gltf",
                                                              "gltf/MorphPrimitivesTest/MorphPrimitivesTest.gltf",
                                                              "gltf/SimpleSkin/SimpleSkin.gltf"),
                                            ::testing::Values(".glb", ".gltf")),
                         [](const auto& sample) {
                           return test::test_name(std::filesystem::path(std::get<0>(sample.param)).filename().string() +
                                                  std::get<1>(sample.param));
                         });

TEST(Gltf, BoxTexturedWeldsItsTwentyFourVerticesIntoEight) {
  for (const char* file : {"gltf/BoxTextured/BoxTextured.glb", "gltf/BoxTextured/BoxTextured.gltf"}) {
    ReadReport report;
    const Mesh mesh = read_mesh(test::data_path(file), &report, keep_faces());
    EXPECT_EQ(report.format, MeshFormat::Gltf);
    EXPECT_EQ(mesh.num_vertices(), 8) << file;
    EXPECT_EQ(mesh.num_faces(), 12) << file;
    EXPECT_EQ(mesh.attributes.gltf->vertex_of_row.size(), 24u) << file;
    const CornerChannel* uv = mesh.attributes.find_corner("uv");
    const CornerChannel* normal = mesh.attributes.find_corner("normal");
    ASSERT_NE(uv, nullptr);
    ASSERT_NE(normal, nullptr);
    EXPECT_EQ(uv->channel.rows(), 24);
    EXPECT_EQ(uv->channel.role, AttributeRole::TexCoord);
    EXPECT_EQ(uv->channel.type, ScalarType::Float32);
    EXPECT_EQ(normal->channel.role, AttributeRole::Normal);
    EXPECT_NE(mesh.attributes.find_face("primitive"), nullptr);
    EXPECT_NE(mesh.attributes.find_face("material"), nullptr);
    EXPECT_EQ(mesh.attributes.materials.size(), 1u);
    EXPECT_EQ(model_of(mesh).images.size(), 1u);
  }
}

TEST(Gltf, SimpleSkinKeepsJointsWeightsAndItsSkin) {
  const Mesh mesh = read_mesh(test::data_path("gltf/SimpleSkin/SimpleSkin.gltf"), nullptr, keep_faces());
  const CornerChannel* joints = mesh.attributes.find_corner("joints");
  const CornerChannel* weights = mesh.attributes.find_corner("weights");
  ASSERT_NE(joints, nullptr);
  ASSERT_NE(weights, nullptr);
  EXPECT_EQ(joints->channel.role, AttributeRole::Label);
  EXPECT_EQ(joints->channel.type, ScalarType::UInt16);
  EXPECT_EQ(weights->channel.role, AttributeRole::Weights);
  EXPECT_EQ(weights->channel.width(), 4);
  test::ScratchDir dir("gltf-skin");
  write_mesh(dir.file("skin.glb"), mesh);
  const Mesh back = read_mesh(dir.file("skin.glb"), nullptr, keep_faces());
  ASSERT_EQ(model_of(back).skins.size(), 1u);
  EXPECT_EQ(model_of(back).skins[0].joints.size(), 2u);
  EXPECT_EQ(model_of(back).animations.size(), 1u);
}

// spot.obj as a fresh document: every corner keeps its position and texture coordinate (as
// float32, what glTF stores).
TEST(Gltf, ObjWrittenAsGlbKeepsPositionsAndTextureCoordinatesPerCorner) {
  const Mesh spot = read_mesh(test::data_path("spot.obj"), nullptr, keep_faces());
  test::ScratchDir dir("gltf-spot");
  write_mesh(dir.file("spot.glb"), spot);
  const Mesh back = read_mesh(dir.file("spot.glb"), nullptr, keep_faces());
  ASSERT_EQ(back.num_faces(), spot.num_faces());
  const CornerChannel* uv = spot.attributes.find_corner("uv");
  const CornerChannel* uv_back = back.attributes.find_corner("uv");
  ASSERT_NE(uv, nullptr);
  ASSERT_NE(uv_back, nullptr);
  int mismatches = 0;
  for (Index f = 0; f < spot.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) {
      for (int c = 0; c < 3; ++c) mismatches += static_cast<float>(spot.V(spot.F(f, k), c)) != back.V(back.F(f, k), c);
      for (int c = 0; c < 2; ++c)
        mismatches += static_cast<float>(uv->channel.values(uv->corners(f, k), c)) !=
                      uv_back->channel.values(uv_back->corners(f, k), c);
    }
  EXPECT_EQ(mismatches, 0);
  EXPECT_EQ(model_of(back).asset.generator, "vertexflow");
}

// spot as a glTF with ubyte skin weights that vary over it, two joints and a skin: after
// enhance moves its vertices, the written file has the same faces, moved texture coordinates,
// its skin, and weights that sum to exactly 255 at every vertex.
std::string skinned_spot_glb(const test::ScratchDir& dir) {
  const Mesh spot = read_mesh(test::data_path("spot.obj"), nullptr, keep_faces());
  write_mesh(dir.file("spot.glb"), spot);
  tinygltf::Model model = model_of(read_mesh(dir.file("spot.glb")));
  EXPECT_EQ(model.meshes.size(), 1u);
  tinygltf::Primitive& primitive = model.meshes[0].primitives.at(0);
  const tinygltf::Accessor& position = model.accessors[static_cast<std::size_t>(primitive.attributes.at("POSITION"))];
  const std::size_t n = position.count;
  const double low = position.minValues[1], high = position.maxValues[1];
  std::vector<unsigned char> joints, weights;
  const auto& data = model.buffers[0].data;
  const auto& view = model.bufferViews[static_cast<std::size_t>(position.bufferView)];
  for (std::size_t i = 0; i < n; ++i) {
    float y = 0;
    std::memcpy(&y, data.data() + view.byteOffset + position.byteOffset + 12 * i + 4, 4);
    const auto w = static_cast<unsigned char>(std::lround(255 * (y - low) / (high - low)));
    joints.insert(joints.end(), {0, 1, 0, 0});
    weights.insert(weights.end(), {w, static_cast<unsigned char>(255 - w), 0, 0});
  }
  auto add = [&](const std::vector<unsigned char>& bytes, bool normalized) {
    auto& buffer = model.buffers[0].data;
    buffer.resize((buffer.size() + 3) / 4 * 4);
    tinygltf::BufferView v;
    v.buffer = 0;
    v.byteOffset = buffer.size();
    v.byteLength = bytes.size();
    v.target = TINYGLTF_TARGET_ARRAY_BUFFER;
    buffer.insert(buffer.end(), bytes.begin(), bytes.end());
    model.bufferViews.push_back(v);
    tinygltf::Accessor a;
    a.bufferView = static_cast<int>(model.bufferViews.size()) - 1;
    a.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;
    a.type = TINYGLTF_TYPE_VEC4;
    a.count = n;
    a.normalized = normalized;
    model.accessors.push_back(a);
    return static_cast<int>(model.accessors.size()) - 1;
  };
  primitive.attributes["JOINTS_0"] = add(joints, false);
  primitive.attributes["WEIGHTS_0"] = add(weights, true);
  model.nodes.resize(3);
  model.nodes[0].skin = 0;
  model.nodes[2].translation = {0, 0.5, 0};
  model.nodes[1].children = {2};
  model.scenes[0].nodes.push_back(1);
  tinygltf::Skin skin;
  skin.joints = {1, 2};
  model.skins.push_back(skin);
  tinygltf::TinyGLTF writer;
  std::ostringstream out;
  EXPECT_TRUE(writer.WriteGltfSceneToStream(&model, out, false, true));
  return out.str();
}

TEST(Gltf, EnhancedSkinnedMeshKeepsItsFacesSkinAndNormalisedWeights) {
  test::ScratchDir dir("gltf-enhance");
  const Mesh mesh =
      read_mesh_from_memory(skinned_spot_glb(dir), MeshFormat::Gltf, "skinned.glb", nullptr, keep_faces());
  const CornerChannel* weights = mesh.attributes.find_corner("weights");
  ASSERT_NE(weights, nullptr);
  EXPECT_EQ(weights->channel.type, ScalarType::UInt8);
  const EnhanceResult result = enhance(mesh, nullptr, EnhanceOptions{});
  write_mesh(dir.file("enhanced.glb"), result.mesh);
  const Mesh back = read_mesh(dir.file("enhanced.glb"), nullptr, keep_faces());

  EXPECT_TRUE(back.F == mesh.F);
  ASSERT_EQ(back.num_vertices(), mesh.num_vertices());
  EXPECT_TRUE(back.V == result.mesh.V.cast<float>().cast<double>());
  const CornerChannel* uv = mesh.attributes.find_corner("uv");
  const CornerChannel* uv_back = back.attributes.find_corner("uv");
  ASSERT_NE(uv, nullptr);
  ASSERT_NE(uv_back, nullptr);
  std::vector<int> moved(static_cast<std::size_t>(mesh.num_vertices()), 0), uv_changed(moved.size(), 0);
  for (Index f = 0; f < mesh.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) {
      const auto v = static_cast<std::size_t>(mesh.F(f, k));
      moved[v] = back.V.row(mesh.F(f, k)) != mesh.V.row(mesh.F(f, k));
      uv_changed[v] |= uv_back->channel.values.row(uv_back->corners(f, k)) != uv->channel.values.row(uv->corners(f, k));
    }
  int num_moved = 0, moved_with_new_uv = 0, unmoved_with_new_uv = 0;
  for (std::size_t v = 0; v < moved.size(); ++v) {
    num_moved += moved[v];
    moved_with_new_uv += moved[v] && uv_changed[v];
    unmoved_with_new_uv += !moved[v] && uv_changed[v];
  }
  EXPECT_GT(num_moved, 100);
  EXPECT_GT(moved_with_new_uv, num_moved * 9 / 10);
  EXPECT_EQ(unmoved_with_new_uv, 0);

  const tinygltf::Model& model = model_of(back);
  ASSERT_EQ(model.skins.size(), 1u);
  EXPECT_EQ(model.skins[0].joints.size(), 2u);
  EXPECT_EQ(model.nodes[0].skin, 0);
  const CornerChannel* weights_back = back.attributes.find_corner("weights");
  ASSERT_NE(weights_back, nullptr);
  int wrong_sums = 0, changed = 0;
  for (Eigen::Index r = 0; r < weights_back->channel.rows(); ++r) {
    wrong_sums += weights_back->channel.values.row(r).sum() != 255.0;
    changed += weights_back->channel.values.row(r) != weights->channel.values.row(r);
  }
  EXPECT_EQ(wrong_sums, 0);
  EXPECT_GT(changed, 0);
  EXPECT_TRUE(back.attributes.find_corner("joints")->channel.values ==
              mesh.attributes.find_corner("joints")->channel.values);
}

std::string base64(const std::string& in) {
  static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (std::size_t i = 0; i < in.size(); i += 3) {
    const std::size_t n = std::min<std::size_t>(3, in.size() - i);
    unsigned v = 0;
    for (std::size_t j = 0; j < 3; ++j) v = v << 8 | (j < n ? static_cast<unsigned char>(in[i + j]) : 0u);
    for (std::size_t j = 0; j < 4; ++j) out += j <= n ? table[(v >> (18 - 6 * j)) & 63] : '=';
  }
  return out;
}

// Three vertices of a non-indexed triangle, drawn again as lines: the triangle is the mesh.
std::string small_gltf(const std::string& extra) {
  std::string bytes;
  for (const float x : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f})
    bytes.append(reinterpret_cast<const char*>(&x), 4);
  return R"({"asset": {"version": "2.0"}, )" + extra +
         R"("buffers": [{"byteLength": 36, "uri": "data:application/octet-stream;base64,)" + base64(bytes) +
         R"("}], "bufferViews": [{"buffer": 0, "byteLength": 36}],
  "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]}],
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}, {"attributes": {"POSITION": 0}, "mode": 1}]}]})";
}

TEST(Gltf, NonIndexedTrianglesAreReadAndLinesReported) {
  ReadReport report;
  const Mesh mesh = read_mesh_from_memory(small_gltf(""), MeshFormat::Gltf, "small.gltf", &report);
  EXPECT_EQ(mesh.num_vertices(), 3);
  EXPECT_EQ(mesh.num_faces(), 1);
  ASSERT_EQ(report.not_kept.size(), 1u);
  EXPECT_EQ(report.not_kept[0], "glTF primitives of mode 1 (lines) (1)");
  EXPECT_FALSE(report.binary);
}

TEST(Gltf, CompressedMeshesAreRefusedInOneLine) {
  for (const char* extension : {"KHR_draco_mesh_compression", "EXT_meshopt_compression"}) {
    const std::string required =
        std::string(R"("extensionsUsed": [")") + extension + R"("], "extensionsRequired": [")" + extension + R"("], )";
    try {
      read_mesh_from_memory(small_gltf(required), MeshFormat::Gltf, "draco.gltf");
      ADD_FAILURE() << extension;
    } catch (const IoError& e) {
      EXPECT_EQ(std::string(e.what()), std::string("draco.gltf: uses ") + extension + ", which vertexflow cannot read");
    }
  }
}

TEST(Gltf, MemoryReadsNoExternalFile) {
  const std::string text = R"({"asset": {"version": "2.0"}, "buffers": [{"byteLength": 36, "uri": "spot.bin"}]})";
  EXPECT_THROW(read_mesh_from_memory(text, MeshFormat::Gltf, "external.gltf"), IoError);
}

}  // namespace
}  // namespace vertexflow
