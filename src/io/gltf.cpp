// glTF 2.0 (io.h, gltf.h) through Debian's tinygltf, whose implementation this file compiles.
// Reading welds each glTF mesh's vertices by position and keeps the document; writing puts the
// mesh's values back into a copy of it (or builds a fresh one for a mesh from another format).
// Images are never decoded: their bytes pass through as they were read.
#define TINYGLTF_IMPLEMENTATION
#include "gltf.h"

#include "io_internal.h"
#include "mesh/position_key.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <unordered_map>

namespace vertexflow::io_detail {
namespace {

constexpr int kByte = TINYGLTF_COMPONENT_TYPE_BYTE;
constexpr int kUByte = TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;
constexpr int kShort = TINYGLTF_COMPONENT_TYPE_SHORT;
constexpr int kUShort = TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;
constexpr int kUInt = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
constexpr int kFloat = TINYGLTF_COMPONENT_TYPE_FLOAT;

// The six component types glTF 2.0 allows, with their sizes; 0 for any other.
int component_size(int type) {
  switch (type) {
    case kByte:
    case kUByte:
      return 1;
    case kShort:
    case kUShort:
      return 2;
    case kUInt:
    case kFloat:
      return 4;
    default:
      return 0;
  }
}

ScalarType scalar_type_of(int type) {
  switch (type) {
    case kByte:
      return ScalarType::Int8;
    case kUByte:
      return ScalarType::UInt8;
    case kShort:
      return ScalarType::Int16;
    case kUShort:
      return ScalarType::UInt16;
    case kUInt:
      return ScalarType::UInt32;
    default:
      return ScalarType::Float32;
  }
}

// The integer that stands for 1.0 in a normalized component of this type.
double normalized_one(int type) {
  return type == kByte ? 127.0 : type == kUByte ? 255.0 : type == kShort ? 32767.0 : 65535.0;
}

double load_component(const unsigned char* p, int type) {
  const bool swap = !host_is_little_endian();
  const char* c = reinterpret_cast<const char*>(p);
  switch (type) {
    case kByte:
      return load_scalar<std::int8_t>(c, swap);
    case kUByte:
      return load_scalar<std::uint8_t>(c, swap);
    case kShort:
      return load_scalar<std::int16_t>(c, swap);
    case kUShort:
      return load_scalar<std::uint16_t>(c, swap);
    case kUInt:
      return load_scalar<std::uint32_t>(c, swap);
    default:
      return load_scalar<float>(c, swap);
  }
}

// `value` must already be what the type holds (to_scalar_type).
void store_component(unsigned char* p, int type, double value) {
  std::string bytes;
  const bool swap = !host_is_little_endian();
  switch (type) {
    case kByte:
      store_scalar<std::int8_t>(bytes, static_cast<std::int8_t>(value), swap);
      break;
    case kUByte:
      store_scalar<std::uint8_t>(bytes, static_cast<std::uint8_t>(value), swap);
      break;
    case kShort:
      store_scalar<std::int16_t>(bytes, static_cast<std::int16_t>(value), swap);
      break;
    case kUShort:
      store_scalar<std::uint16_t>(bytes, static_cast<std::uint16_t>(value), swap);
      break;
    case kUInt:
      store_scalar<std::uint32_t>(bytes, static_cast<std::uint32_t>(value), swap);
      break;
    default:
      store_scalar<float>(bytes, static_cast<float>(value), swap);
      break;
  }
  std::memcpy(p, bytes.data(), bytes.size());
}

// An accessor whose every byte was checked to lie inside its buffers: element i, component c
// is at base + i * stride + c * size (when it has a bufferView), and sparse substitutions
// replace some elements on reading.
struct AccessorView {
  int index = -1;
  int type = kFloat;  // component type
  int size = 4;       // component size
  int components = 1;
  std::size_t count = 0;
  std::size_t stride = 0;
  bool normalized = false;
  bool sparse = false;
  unsigned char* base = nullptr;  // null: no bufferView (zeros)
  std::size_t sparse_count = 0;
  int sparse_index_type = kUInt;
  const unsigned char* sparse_indices = nullptr;
  const unsigned char* sparse_values = nullptr;
  int buffer_view = -1;
  int sparse_views[2] = {-1, -1};

  [[nodiscard]] bool integer() const { return type != kFloat; }
  [[nodiscard]] unsigned char* at(std::size_t i, int c) const {
    return base + i * stride + static_cast<std::size_t>(c) * static_cast<std::size_t>(size);
  }
};

// The bytes [offset, offset + length) of bufferView `view`, checked; `what` names it in errors.
unsigned char* view_bytes(tinygltf::Model& model, int view, std::size_t offset, std::size_t length,
                          const std::string& name, const std::string& what) {
  if (view < 0 || static_cast<std::size_t>(view) >= model.bufferViews.size())
    fail(name, fmt::format("{} refers to bufferView {}, which does not exist", what, view));
  const tinygltf::BufferView& bv = model.bufferViews[static_cast<std::size_t>(view)];
  if (bv.buffer < 0 || static_cast<std::size_t>(bv.buffer) >= model.buffers.size())
    fail(name, fmt::format("bufferView {} refers to buffer {}, which does not exist", view, bv.buffer));
  std::vector<unsigned char>& data = model.buffers[static_cast<std::size_t>(bv.buffer)].data;
  if (bv.byteOffset > data.size() || bv.byteLength > data.size() - bv.byteOffset)
    fail(name, fmt::format("bufferView {} reaches past the end of buffer {} ({} bytes)", view, bv.buffer, data.size()));
  if (offset > bv.byteLength || length > bv.byteLength - offset)
    fail(name, fmt::format("{} reaches past the end of bufferView {}", what, view));
  return data.data() + bv.byteOffset + offset;
}

AccessorView view_accessor(tinygltf::Model& model, int index, const std::string& name) {
  if (index < 0 || static_cast<std::size_t>(index) >= model.accessors.size())
    fail(name, fmt::format("accessor {} does not exist", index));
  const tinygltf::Accessor& a = model.accessors[static_cast<std::size_t>(index)];
  const std::string what = fmt::format("accessor {}", index);
  AccessorView v;
  v.index = index;
  v.type = a.componentType;
  v.size = component_size(a.componentType);
  if (v.size == 0)
    fail(name, fmt::format("{} has component type {}, which glTF 2.0 does not allow", what, a.componentType));
  v.components = tinygltf::GetNumComponentsInType(static_cast<std::uint32_t>(a.type));
  if (v.components <= 0) fail(name, fmt::format("{} has an unknown type {}", what, a.type));
  v.count = a.count;
  v.normalized = a.normalized;
  const std::size_t element = static_cast<std::size_t>(v.size) * static_cast<std::size_t>(v.components);
  if (a.bufferView >= 0) {
    if (static_cast<std::size_t>(a.bufferView) >= model.bufferViews.size())
      fail(name, fmt::format("{} refers to bufferView {}, which does not exist", what, a.bufferView));
    const tinygltf::BufferView& bv = model.bufferViews[static_cast<std::size_t>(a.bufferView)];
    v.stride = bv.byteStride != 0 ? bv.byteStride : element;
    if (v.stride < element) fail(name, fmt::format("{} has elements larger than its byteStride", what));
    // count elements of `element` bytes, `stride` apart, after byteOffset (no overflow: a
    // count larger than the view's length is refused before the product).
    std::size_t length = 0;
    if (v.count > 0) {
      if (v.count > bv.byteLength)
        fail(name, fmt::format("{} reaches past the end of bufferView {}", what, a.bufferView));
      length = (v.count - 1) * v.stride + element;
    }
    v.base = view_bytes(model, a.bufferView, a.byteOffset, length, name, what);
    v.buffer_view = a.bufferView;
  } else if (v.count > (std::size_t{1} << 20)) {
    // Zeros (or sparse values) that no byte of the file backs: bounded, so that memory stays
    // bounded by the file's size.
    fail(name, fmt::format("{} has {} elements but no bufferView", what, v.count));
  }
  if (a.sparse.isSparse) {
    v.sparse = true;
    if (a.sparse.count < 0 || static_cast<std::size_t>(a.sparse.count) > v.count)
      fail(name, fmt::format("{} has a sparse count {} beyond its {} elements", what, a.sparse.count, v.count));
    v.sparse_count = static_cast<std::size_t>(a.sparse.count);
    v.sparse_index_type = a.sparse.indices.componentType;
    if (v.sparse_index_type != kUByte && v.sparse_index_type != kUShort && v.sparse_index_type != kUInt)
      fail(name, fmt::format("{} has sparse indices of component type {}", what, v.sparse_index_type));
    if (a.sparse.indices.byteOffset < 0 || a.sparse.values.byteOffset < 0)
      fail(name, fmt::format("{} has a negative sparse byteOffset", what));
    v.sparse_indices =
        view_bytes(model, a.sparse.indices.bufferView, static_cast<std::size_t>(a.sparse.indices.byteOffset),
                   v.sparse_count * static_cast<std::size_t>(component_size(v.sparse_index_type)), name,
                   what + " (sparse indices)");
    v.sparse_values =
        view_bytes(model, a.sparse.values.bufferView, static_cast<std::size_t>(a.sparse.values.byteOffset),
                   v.sparse_count * element, name, what + " (sparse values)");
    v.sparse_views[0] = a.sparse.indices.bufferView;
    v.sparse_views[1] = a.sparse.values.bufferView;
  }
  return v;
}

// Every element's components as stored (integers as integers), sparse substitutions applied.
std::vector<double> read_values(const AccessorView& v, const std::string& name) {
  const auto width = static_cast<std::size_t>(v.components);
  std::vector<double> out(v.count * width, 0.0);
  if (v.base != nullptr)
    for (std::size_t i = 0; i < v.count; ++i)
      for (int c = 0; c < v.components; ++c)
        out[i * width + static_cast<std::size_t>(c)] = load_component(v.at(i, c), v.type);
  const auto index_size = static_cast<std::size_t>(component_size(v.sparse_index_type));
  for (std::size_t s = 0; s < v.sparse_count; ++s) {
    const double i = load_component(v.sparse_indices + s * index_size, v.sparse_index_type);
    if (i >= static_cast<double>(v.count))
      fail(name, fmt::format("accessor {} has a sparse index {} past its {} elements", v.index, i, v.count));
    for (int c = 0; c < v.components; ++c)
      out[static_cast<std::size_t>(i) * width + static_cast<std::size_t>(c)] = load_component(
          v.sparse_values + (s * width + static_cast<std::size_t>(c)) * static_cast<std::size_t>(v.size), v.type);
  }
  return out;
}

// POSITION and NORMAL in a normalized integer type (KHR_mesh_quantization) are held as the
// numbers they stand for, so that the geometry and the recomputed normals mean what they say;
// every other attribute holds the stored integers (they interpolate the same way).
bool dequantized(const std::string& attribute, const AccessorView& v) {
  return v.normalized && v.integer() && (attribute == "POSITION" || attribute == "NORMAL");
}

double dequantize(double raw, int type) {
  return std::max(raw / normalized_one(type), -1.0);
}

// The value `value` is stored as in an accessor element of `v` (an attribute `attribute`).
double stored_value(double value, const AccessorView& v, const std::string& attribute) {
  if (dequantized(attribute, v)) value *= normalized_one(v.type);
  return to_scalar_type(value, scalar_type_of(v.type));
}

const char* mode_name(int mode) {
  switch (mode) {
    case TINYGLTF_MODE_POINTS:
      return "points";
    case TINYGLTF_MODE_LINE:
      return "lines";
    case TINYGLTF_MODE_LINE_LOOP:
      return "line loop";
    case TINYGLTF_MODE_LINE_STRIP:
      return "line strip";
    case TINYGLTF_MODE_TRIANGLE_STRIP:
      return "triangle strip";
    case TINYGLTF_MODE_TRIANGLE_FAN:
      return "triangle fan";
    default:
      return "unknown";
  }
}

// The compressions whose data tinygltf cannot decode: the accessors hold no usable values.
void refuse_compression(const std::vector<std::string>& required, const std::string& name) {
  for (const std::string& extension : required)
    if (extension == "KHR_draco_mesh_compression" || extension == "EXT_meshopt_compression" ||
        extension == "KHR_meshopt_compression")
      fail(name, "uses " + extension + ", which vertexflow cannot read");
}

// extensionsRequired from the JSON itself, for a document tinygltf refused (a Draco file has
// accessors without bufferViews, which tinygltf rejects before we see the extension).
std::vector<std::string> required_extensions(std::string_view bytes, bool binary) {
  std::string_view text = bytes;
  if (binary) {
    if (bytes.size() < 20) return {};
    const auto length = load_scalar<std::uint32_t>(bytes.data() + 12, !host_is_little_endian());
    text = bytes.substr(20, length);
  }
  const nlohmann::json json = nlohmann::json::parse(text.begin(), text.end(), nullptr, /*allow_exceptions=*/false);
  std::vector<std::string> out;
  if (!json.is_object()) return out;
  const auto it = json.find("extensionsRequired");
  if (it == json.end() || !it->is_array()) return out;
  for (const auto& e : *it)
    if (e.is_string()) out.push_back(e.get<std::string>());
  return out;
}

std::string first_line(const std::string& text) {
  std::string line;
  std::istringstream in(text);
  while (std::getline(in, line)) {
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
    if (!line.empty()) return line;
  }
  return "unknown error";
}

// Images keep their encoded bytes: nothing is decoded, and writing puts the same bytes back.
bool keep_image_bytes(tinygltf::Image* image, const int, std::string*, std::string*, int, int,
                      const unsigned char* bytes, int size, void*) {
  image->image.assign(bytes, bytes + size);
  image->as_is = true;
  return true;
}

// Reading from memory reads no file: a .gltf there must embed its buffers and images.
bool no_file_exists(const std::string&, void*) {
  return false;
}
std::string same_path(const std::string& path, void*) {
  return path;
}
bool no_file_read(std::vector<unsigned char>*, std::string* err, const std::string& path, void*) {
  if (err) *err += "external file '" + path + "' cannot be read from memory\n";
  return false;
}
bool no_file_write(std::string*, const std::string&, const std::vector<unsigned char>&, void*) {
  return false;
}

std::shared_ptr<GltfDocument> load_document(std::string_view bytes, const std::string& name,
                                            const std::filesystem::path& base_directory, bool read_files) {
  if (bytes.empty()) fail(name, "the file is empty");
  if (bytes.size() > std::numeric_limits<unsigned int>::max())
    fail(name, "glTF files of 4 GiB or more are not supported");
  auto document = std::make_shared<GltfDocument>();
  document->binary = bytes.substr(0, 4) == "glTF";
  document->base_directory = base_directory;
  tinygltf::TinyGLTF loader;
  loader.SetImageLoader(keep_image_bytes, nullptr);
  loader.SetStoreOriginalJSONForExtrasAndExtensions(false);
  if (!read_files) loader.SetFsCallbacks({no_file_exists, same_path, no_file_read, no_file_write, nullptr});
  std::string error, warning;
  const std::string base = base_directory.empty() ? std::string() : base_directory.string();
  bool ok = false;
  try {
    ok = document->binary ? loader.LoadBinaryFromMemory(&document->model, &error, &warning,
                                                        reinterpret_cast<const unsigned char*>(bytes.data()),
                                                        static_cast<unsigned int>(bytes.size()), base)
                          : loader.LoadASCIIFromString(&document->model, &error, &warning, bytes.data(),
                                                       static_cast<unsigned int>(bytes.size()), base);
  } catch (const std::bad_alloc&) {
    throw;
  } catch (const std::exception& e) {
    error = e.what();
  }
  if (!ok) {
    refuse_compression(required_extensions(bytes, document->binary), name);
    fail(name, "not a valid glTF file: " + first_line(error));
  }
  refuse_compression(document->model.extensionsRequired, name);
  return document;
}

// A glTF attribute as a corner channel: its name, role and component names.
struct Semantic {
  std::string channel;
  AttributeRole role = AttributeRole::Generic;
  std::vector<std::string> components;
};

Semantic semantic_of(const std::string& attribute, int width, bool label) {
  auto numbered = [&](std::string_view prefix, const char* base) -> std::optional<std::string> {
    if (attribute.rfind(prefix, 0) != 0) return std::nullopt;
    const std::string n = attribute.substr(prefix.size());
    return n == "0" ? std::string(base) : std::string(base) + n;
  };
  Semantic s;
  std::vector<std::string> names = {"x", "y", "z", "w"};
  if (attribute == "NORMAL") {
    s = {"normal", AttributeRole::Normal, {}};
  } else if (attribute == "TANGENT") {
    s = {"tangent", AttributeRole::Generic, {}};
  } else if (auto uv = numbered("TEXCOORD_", "uv")) {
    s = {*uv, AttributeRole::TexCoord, {}};
    names = {"u", "v"};
  } else if (auto color = numbered("COLOR_", "color")) {
    s = {*color, AttributeRole::Color, {}};
    names = {"r", "g", "b", "a"};
  } else if (auto joints = numbered("JOINTS_", "joints")) {
    s = {*joints, AttributeRole::Label, {}};
    names = {"j0", "j1", "j2", "j3"};
  } else if (auto weights = numbered("WEIGHTS_", "weights")) {
    s = {*weights, AttributeRole::Weights, {}};
    names = {"w0", "w1", "w2", "w3"};
  } else {  // an application-specific attribute ("_BATCHID"): by its own name
    s = {attribute, label ? AttributeRole::Label : AttributeRole::Generic, {}};
  }
  for (int c = 0; c < width; ++c)
    s.components.push_back(static_cast<std::size_t>(c) < names.size() ? names[static_cast<std::size_t>(c)]
                                                                      : fmt::format("c{}", c));
  return s;
}

// A corner channel being gathered: the rows of each primitive that has it.
struct PendingChannel {
  std::string attribute;
  Semantic semantic;
  int width = 0;
  ScalarType type = ScalarType::Float32;
  bool mixed = false;
  std::vector<std::pair<std::size_t, std::vector<double>>> parts;  // (primitive, rows x its width)
  std::vector<int> part_width;
};

Mesh build_mesh(std::shared_ptr<GltfDocument> document, const std::string& name, ReadReport& report,
                const ReadOptions& options) {
  GltfDocument& doc = *document;
  tinygltf::Model& model = doc.model;
  report.binary = doc.binary;
  PolygonSoup soup;
  std::vector<PendingChannel> channels;
  std::vector<std::int32_t> face_rows;  // 3 per face
  std::vector<double> primitive_label, material_label;
  std::unordered_map<PositionKey, Index, PositionKeyHash> welded;
  std::int64_t rows = 0;
  for (std::size_t m = 0; m < model.meshes.size(); ++m) {
    welded.clear();  // vertices weld within one glTF mesh only
    const tinygltf::Mesh& mesh = model.meshes[m];
    for (std::size_t p = 0; p < mesh.primitives.size(); ++p) {
      const tinygltf::Primitive& primitive = mesh.primitives[p];
      const std::string where = fmt::format("mesh {} primitive {}", m, p);
      if (primitive.mode != TINYGLTF_MODE_TRIANGLES) {
        soup.count_not_kept(fmt::format("glTF primitives of mode {} ({})", primitive.mode, mode_name(primitive.mode)));
        continue;
      }
      const auto position = primitive.attributes.find("POSITION");
      if (position == primitive.attributes.end()) {
        soup.count_not_kept("glTF primitives without POSITION");
        continue;
      }
      const AccessorView positions = view_accessor(model, position->second, name);
      if (positions.components != 3) fail(name, where + ": POSITION is not a VEC3 accessor");
      std::vector<double> triangles;
      if (primitive.indices >= 0) {
        const AccessorView indices = view_accessor(model, primitive.indices, name);
        if (indices.components != 1 || (indices.type != kUByte && indices.type != kUShort && indices.type != kUInt))
          fail(name, where + ": indices are not unsigned integer scalars");
        triangles = read_values(indices, name);
      } else {  // non-indexed: vertices 3t, 3t+1, 3t+2 make triangle t
        triangles.resize(positions.count);
        for (std::size_t i = 0; i < positions.count; ++i) triangles[i] = static_cast<double>(i);
      }
      triangles.resize(triangles.size() / 3 * 3);
      for (const double index : triangles)
        if (index >= static_cast<double>(positions.count))
          fail(name, fmt::format("{}: index {} is past its {} vertices", where, index, positions.count));
      if (primitive.material >= static_cast<int>(model.materials.size()))
        fail(name, fmt::format("{}: material {} does not exist", where, primitive.material));
      const std::size_t kept = doc.primitives.size();
      GltfDocument::Primitive& record = doc.primitives.emplace_back();
      record.mesh = static_cast<int>(m);
      record.primitive = static_cast<int>(p);
      record.first_vertex = rows;
      record.num_vertices = static_cast<std::int64_t>(positions.count);
      record.first_face = static_cast<std::int64_t>(face_rows.size() / 3);
      record.num_faces = static_cast<std::int64_t>(triangles.size() / 3);
      if (rows + record.num_vertices > std::numeric_limits<std::int32_t>::max())
        fail(name, "more than 2^31-1 glTF vertices are not supported");

      std::vector<double> xyz = read_values(positions, name);
      for (std::size_t i = 0; i < positions.count; ++i) {
        if (dequantized("POSITION", positions))
          for (std::size_t c = 0; c < 3; ++c) xyz[3 * i + c] = dequantize(xyz[3 * i + c], positions.type);
        const auto [it, inserted] =
            welded.try_emplace(position_key(xyz.data() + 3 * i), static_cast<Index>(soup.num_vertices()));
        if (inserted) soup.add_vertex(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
        doc.vertex_of_row.push_back(it->second);
      }
      for (const double index : triangles)
        face_rows.push_back(static_cast<std::int32_t>(rows + static_cast<std::int64_t>(index)));
      primitive_label.resize(face_rows.size() / 3, static_cast<double>(kept));
      material_label.resize(face_rows.size() / 3, static_cast<double>(primitive.material));

      for (const auto& entry : primitive.attributes) {
        const std::string& attribute = entry.first;
        const int accessor = entry.second;
        if (attribute == "POSITION") continue;
        const AccessorView view = view_accessor(model, accessor, name);
        if (view.count != positions.count)
          fail(name,
               fmt::format("{}: {} has {} elements for {} vertices", where, attribute, view.count, positions.count));
        if (tinygltf::GetNumComponentsInType(static_cast<std::uint32_t>(
                model.accessors[static_cast<std::size_t>(accessor)].type)) != view.components ||
            view.components > 4 || model.accessors[static_cast<std::size_t>(accessor)].type >= TINYGLTF_TYPE_MAT2) {
          soup.count_not_kept("glTF matrix attributes " + attribute);
          continue;
        }
        auto it = std::find_if(channels.begin(), channels.end(),
                               [&](const PendingChannel& c) { return c.attribute == attribute; });
        const ScalarType type = dequantized(attribute, view) ? ScalarType::Float32 : scalar_type_of(view.type);
        if (it == channels.end()) {
          PendingChannel& c = channels.emplace_back();
          c.attribute = attribute;
          c.type = type;
          it = std::prev(channels.end());
        }
        PendingChannel& channel = *it;
        if (channel.type != type) channel.mixed = true;
        channel.width = std::max(channel.width, view.components);
        channel.semantic = semantic_of(attribute, channel.width, view.integer() && !view.normalized);
        std::vector<double> values = read_values(view, name);
        if (dequantized(attribute, view))
          for (double& x : values) x = dequantize(x, view.type);
        channel.parts.emplace_back(kept, std::move(values));
        channel.part_width.push_back(view.components);
      }
      rows += record.num_vertices;
    }
  }
  if (doc.primitives.empty()) fail(name, "has no triangle primitives");
  if (face_rows.empty()) fail(name, "the file contains no faces");

  const std::size_t num_faces = face_rows.size() / 3;
  for (std::size_t f = 0; f < num_faces; ++f) {
    for (std::size_t k = 0; k < 3; ++k)
      soup.corners.push_back(doc.vertex_of_row[static_cast<std::size_t>(face_rows[3 * f + k])]);
    soup.end_polygon();
  }
  std::vector<std::size_t> primitive_of_face(num_faces);
  for (std::size_t i = 0; i < doc.primitives.size(); ++i)
    for (std::int64_t f = 0; f < doc.primitives[i].num_faces; ++f)
      primitive_of_face[static_cast<std::size_t>(doc.primitives[i].first_face + f)] = i;
  for (PendingChannel& pending : channels) {
    AttributeChannel channel;
    channel.name = pending.semantic.channel;
    channel.components = pending.semantic.components;
    channel.role = pending.semantic.role;
    channel.type = pending.mixed ? ScalarType::Float64 : pending.type;  // Float64 holds every type's values
    channel.values.setZero(rows, pending.width);
    std::vector<char> present(doc.primitives.size(), 0);
    for (std::size_t part = 0; part < pending.parts.size(); ++part) {
      const auto& [primitive, values] = pending.parts[part];
      const GltfDocument::Primitive& record = doc.primitives[primitive];
      const auto width = static_cast<std::size_t>(pending.part_width[part]);
      present[primitive] = 1;
      for (std::int64_t i = 0; i < record.num_vertices; ++i)
        for (std::size_t c = 0; c < width; ++c)
          channel.values(record.first_vertex + i, static_cast<Eigen::Index>(c)) =
              values[static_cast<std::size_t>(i) * width + c];
    }
    std::vector<std::int32_t> corner_rows(face_rows.size(), -1);
    for (std::size_t f = 0; f < num_faces; ++f)
      if (present[primitive_of_face[f]])
        for (std::size_t k = 0; k < 3; ++k) corner_rows[3 * f + k] = face_rows[3 * f + k];
    doc.channel_attributes.emplace_back(channel.name, pending.attribute);
    soup.attributes.corner.push_back({std::move(channel), {}});
    soup.corner_rows.push_back(std::move(corner_rows));
  }
  soup.attributes.face.push_back(
      make_channel("primitive", {"primitive"}, ScalarType::Int32, AttributeRole::Label, {primitive_label}));
  soup.attributes.face.push_back(
      make_channel("material", {"material"}, ScalarType::Int32, AttributeRole::Label, {material_label}));
  for (std::size_t i = 0; i < model.materials.size(); ++i)
    soup.attributes.materials.push_back(model.materials[i].name.empty() ? fmt::format("material {}", i)
                                                                        : model.materials[i].name);

  doc.face_rows = Eigen::Map<const Eigen::Matrix<std::int32_t, Eigen::Dynamic, 3, Eigen::RowMajor>>(
      face_rows.data(), static_cast<Eigen::Index>(num_faces), 3);
  doc.num_vertices = static_cast<Index>(soup.num_vertices());
  // The face list is always the file's, so that every face and vertex stays where the document
  // has it (faces with a repeated vertex after welding are kept and counted).
  ReadOptions keep = options;
  keep.keep_face_list = true;
  Mesh out = soup_to_mesh(std::move(soup), name, report, keep);
  out.attributes.gltf = std::move(document);
  return out;
}

// ---- Writing ----

std::string base64(const std::vector<unsigned char>& in) {
  static constexpr char table[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((in.size() + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 2 < in.size(); i += 3) {
    const unsigned v = (unsigned{in[i]} << 16) | (unsigned{in[i + 1]} << 8) | in[i + 2];
    for (int s = 18; s >= 0; s -= 6) out += table[(v >> s) & 63];
  }
  if (i + 1 == in.size()) {
    const unsigned v = unsigned{in[i]} << 16;
    out += table[v >> 18];
    out += table[(v >> 12) & 63];
    out += "==";
  } else if (i + 2 == in.size()) {
    const unsigned v = (unsigned{in[i]} << 16) | (unsigned{in[i + 1]} << 8);
    out += table[v >> 18];
    out += table[(v >> 12) & 63];
    out += table[(v >> 6) & 63];
    out += '=';
  }
  return out;
}

std::string mime_type_of(const tinygltf::Image& image) {
  if (!image.mimeType.empty()) return image.mimeType;
  const auto& d = image.image;
  if (d.size() > 3 && d[0] == 0x89 && d[1] == 'P' && d[2] == 'N' && d[3] == 'G') return "image/png";
  if (d.size() > 2 && d[0] == 0xFF && d[1] == 0xD8) return "image/jpeg";
  return "application/octet-stream";
}

// A URI reference for a file name: unreserved characters as they are, the rest %XX.
std::string percent_encoded(const std::string& name) {
  std::string out;
  for (const char ch : name) {
    const auto c = static_cast<unsigned char>(ch);
    if (std::isalnum(c) || c == '-' || c == '.' || c == '_' || c == '~')
      out += ch;
    else
      out += fmt::format("%{:02X}", c);
  }
  return out;
}

std::string percent_decoded(const std::string& uri) {
  std::string out;
  for (std::size_t i = 0; i < uri.size(); ++i) {
    if (uri[i] == '%' && i + 2 < uri.size() && std::isxdigit(static_cast<unsigned char>(uri[i + 1])) &&
        std::isxdigit(static_cast<unsigned char>(uri[i + 2]))) {
      out += static_cast<char>(std::stoi(uri.substr(i + 1, 2), nullptr, 16));
      i += 2;
    } else {
      out += uri[i];
    }
  }
  return out;
}

// The mesh's document, when it still describes the mesh: the same vertices and faces.
const GltfDocument* usable_document(const Mesh& mesh) {
  const GltfDocument* doc = mesh.attributes.gltf.get();
  if (doc == nullptr || mesh.V.rows() != doc->num_vertices || mesh.F.rows() != doc->face_rows.rows()) return nullptr;
  return doc;
}

const std::string* attribute_of(const GltfDocument& doc, const std::string& channel) {
  for (const auto& [name, attribute] : doc.channel_attributes)
    if (name == channel) return &attribute;
  return nullptr;
}

// Writes element `i` of `v` (an attribute `attribute`) where its stored value differs from
// `values`; returns whether it did. Weights in a normalized integer type are made to sum to
// exactly the type's one after rounding (the largest absorbs the difference).
bool write_element(const AccessorView& v, std::size_t i, const double* values, int width, const std::string& attribute,
                   std::vector<char>& touched_views, const std::string& name) {
  const int n = std::min(width, v.components);
  std::array<double, 4> stored{};
  bool differs = false;
  for (int c = 0; c < n; ++c) {
    stored[static_cast<std::size_t>(c)] = stored_value(values[c], v, attribute);
    const double current = v.base ? load_component(v.at(i, c), v.type) : 0.0;
    differs |= !(stored[static_cast<std::size_t>(c)] == current);
  }
  if (!differs) return false;
  if (v.sparse || v.base == nullptr)
    fail(name, fmt::format("cannot write: accessor {} ({}) is {}, and its values changed", v.index, attribute,
                           v.sparse ? "sparse" : "without a bufferView"));
  if (attribute.rfind("WEIGHTS_", 0) == 0 && v.normalized && v.integer() && n > 0) {
    const double one = normalized_one(v.type);
    double sum = 0;
    int largest = 0;
    for (int c = 0; c < n; ++c) {
      sum += stored[static_cast<std::size_t>(c)];
      if (stored[static_cast<std::size_t>(c)] > stored[static_cast<std::size_t>(largest)]) largest = c;
    }
    if (sum > 0)
      stored[static_cast<std::size_t>(largest)] =
          std::clamp(stored[static_cast<std::size_t>(largest)] + one - sum, 0.0, one);
  }
  for (int c = 0; c < n; ++c) store_component(v.at(i, c), v.type, stored[static_cast<std::size_t>(c)]);
  touched_views[static_cast<std::size_t>(v.buffer_view)] = 1;
  return true;
}

void recompute_bounds(tinygltf::Model& model, const std::vector<char>& touched_views,
                      const std::vector<char>& needs_bounds, const std::string& name) {
  for (std::size_t a = 0; a < model.accessors.size(); ++a) {
    tinygltf::Accessor& accessor = model.accessors[a];
    auto touched = [&](int view) { return view >= 0 && touched_views[static_cast<std::size_t>(view)]; };
    if (!touched(accessor.bufferView) && !(accessor.sparse.isSparse && (touched(accessor.sparse.indices.bufferView) ||
                                                                        touched(accessor.sparse.values.bufferView))))
      continue;
    if (accessor.minValues.empty() && accessor.maxValues.empty() && !needs_bounds[a]) continue;
    const AccessorView v = view_accessor(model, static_cast<int>(a), name);
    const std::vector<double> values = read_values(v, name);
    const auto width = static_cast<std::size_t>(v.components);
    std::vector<double> lo(width, std::numeric_limits<double>::infinity()),
        hi(width, -std::numeric_limits<double>::infinity());
    for (std::size_t i = 0; i < v.count; ++i)
      for (std::size_t c = 0; c < width; ++c) {
        lo[c] = std::min(lo[c], values[i * width + c]);
        hi[c] = std::max(hi[c], values[i * width + c]);
      }
    if (v.count == 0) continue;
    accessor.minValues = lo;
    accessor.maxValues = hi;
  }
}

// The document with the mesh's positions, corner channels and faces written into its accessors.
tinygltf::Model fill_document(const GltfDocument& doc, const Mesh& mesh, const std::string& name) {
  tinygltf::Model model = doc.model;
  const auto rows = static_cast<std::int64_t>(doc.vertex_of_row.size());
  const Index num_faces = mesh.num_faces();
  std::vector<std::size_t> primitive_of_face(static_cast<std::size_t>(num_faces));
  for (std::size_t i = 0; i < doc.primitives.size(); ++i)
    for (std::int64_t f = 0; f < doc.primitives[i].num_faces; ++f)
      primitive_of_face[static_cast<std::size_t>(doc.primitives[i].first_face + f)] = i;
  auto primitive_of = [&](const GltfDocument::Primitive& p) -> const tinygltf::Primitive& {
    return model.meshes[static_cast<std::size_t>(p.mesh)].primitives[static_cast<std::size_t>(p.primitive)];
  };

  // The glTF vertex each face corner writes: the one it was read from, unless an edge flip
  // changed the face; then one of its primitive at the corner's vertex, preferably the row a
  // corner channel gives it (the neighbouring face's, in the same chart).
  Eigen::Matrix<std::int32_t, Eigen::Dynamic, 3, Eigen::RowMajor> target = doc.face_rows;
  std::unordered_map<std::uint64_t, std::int32_t> row_at;  // (primitive, vertex) -> a referenced row
  for (Index f = 0; f < num_faces; ++f) {
    bool same = true;
    for (int k = 0; k < 3; ++k)
      same &= doc.vertex_of_row[static_cast<std::size_t>(doc.face_rows(f, k))] == mesh.F(f, k);
    const std::size_t pi = primitive_of_face[static_cast<std::size_t>(f)];
    const GltfDocument::Primitive& p = doc.primitives[pi];
    if (same || primitive_of(p).indices < 0) continue;  // non-indexed: the face's own three rows take the new values
    for (int k = 0; k < 3; ++k) {
      const Index x = mesh.F(f, k);
      std::int32_t g = -1;
      for (const CornerChannel& c : mesh.attributes.corner) {
        const std::int32_t q = c.corners(f, k);
        if (attribute_of(doc, c.channel.name) && q >= p.first_vertex && q < p.first_vertex + p.num_vertices &&
            doc.vertex_of_row[static_cast<std::size_t>(q)] == x) {
          g = q;
          break;
        }
      }
      if (g < 0) {
        if (row_at.empty())
          for (Index h = doc.face_rows.rows() - 1; h >= 0; --h)
            for (int j = 0; j < 3; ++j) {
              const std::int32_t r = doc.face_rows(h, j);
              row_at[(std::uint64_t{primitive_of_face[static_cast<std::size_t>(h)]} << 32) |
                     static_cast<std::uint32_t>(doc.vertex_of_row[static_cast<std::size_t>(r)])] = r;
            }
        const auto it = row_at.find((std::uint64_t{pi} << 32) | static_cast<std::uint32_t>(x));
        if (it == row_at.end())
          fail(name, fmt::format("cannot write: face {} has vertex {}, which its glTF primitive does not have", f, x));
        g = it->second;
      }
      target(f, k) = g;
    }
  }

  std::vector<char> touched(model.bufferViews.size(), 0), needs_bounds(model.accessors.size(), 0);
  // POSITION: every glTF vertex at its vertex, then each face corner at its own (the same,
  // except in a non-indexed primitive whose faces were flipped).
  Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> positions(rows, 3);
  for (std::int64_t r = 0; r < rows; ++r) positions.row(r) = mesh.V.row(doc.vertex_of_row[static_cast<std::size_t>(r)]);
  for (Index f = 0; f < num_faces; ++f)
    for (int k = 0; k < 3; ++k) positions.row(target(f, k)) = mesh.V.row(mesh.F(f, k));
  for (const GltfDocument::Primitive& p : doc.primitives) {
    const int accessor = primitive_of(p).attributes.at("POSITION");
    const AccessorView v = view_accessor(model, accessor, name);
    needs_bounds[static_cast<std::size_t>(accessor)] = 1;
    for (std::int64_t i = 0; i < p.num_vertices; ++i)
      write_element(v, static_cast<std::size_t>(i), positions.row(p.first_vertex + i).data(), 3, "POSITION", touched,
                    name);
  }

  // Corner channels: each corner's row into the glTF vertex it writes.
  for (const CornerChannel& c : mesh.attributes.corner) {
    const std::string* attribute = attribute_of(doc, c.channel.name);
    if (attribute == nullptr) continue;
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> values(rows, c.channel.width());
    std::vector<char> set(static_cast<std::size_t>(rows), 0);
    for (Index f = 0; f < num_faces; ++f)
      for (int k = 0; k < 3; ++k) {
        const std::int32_t q = c.corners(f, k);
        if (q < 0) continue;
        values.row(target(f, k)) = c.channel.values.row(q);
        set[static_cast<std::size_t>(target(f, k))] = 1;
      }
    for (const GltfDocument::Primitive& p : doc.primitives) {
      const auto found = primitive_of(p).attributes.find(*attribute);
      if (found == primitive_of(p).attributes.end()) continue;
      const AccessorView v = view_accessor(model, found->second, name);
      for (std::int64_t i = 0; i < p.num_vertices; ++i)
        if (set[static_cast<std::size_t>(p.first_vertex + i)])
          write_element(v, static_cast<std::size_t>(i), values.row(p.first_vertex + i).data(), c.channel.width(),
                        *attribute, touched, name);
    }
  }

  // Indices, where faces changed.
  for (const GltfDocument::Primitive& p : doc.primitives) {
    const int indices = primitive_of(p).indices;
    if (indices < 0) continue;
    const AccessorView v = view_accessor(model, indices, name);
    const double most = v.type == kUByte ? 255.0 : v.type == kUShort ? 65535.0 : 4294967295.0;
    for (std::int64_t t = 0; t < p.num_faces; ++t)
      for (int k = 0; k < 3; ++k) {
        const double local = static_cast<double>(target(p.first_face + t, k) - p.first_vertex);
        if (local > most)
          fail(name, fmt::format("cannot write: glTF vertex {} does not fit accessor {}'s index type", local, indices));
        const auto i = static_cast<std::size_t>(3 * t + k);
        if (v.base != nullptr && !v.sparse && load_component(v.at(i, 0), v.type) == local) continue;
        if (v.sparse || v.base == nullptr) {
          const std::vector<double> current = read_values(v, name);
          if (current[i] == local) continue;
          fail(name, fmt::format("cannot write: accessor {} (indices) is sparse, and its faces changed", indices));
        }
        store_component(v.at(i, 0), v.type, local);
        touched[static_cast<std::size_t>(v.buffer_view)] = 1;
      }
  }
  recompute_bounds(model, touched, needs_bounds, name);
  return model;
}

// What a mesh from another format is written with: one texture coordinate, normal and colour
// channel each, per vertex or per corner.
struct FreshChannels {
  const AttributeChannel* uv = nullptr;
  const AttributeChannel* normal = nullptr;
  const AttributeChannel* color = nullptr;
  const CornerChannel* corner_uv = nullptr;
  const CornerChannel* corner_normal = nullptr;
  const CornerChannel* corner_color = nullptr;
  const AttributeChannel* material = nullptr;
};

FreshChannels fresh_channels(const Mesh& mesh) {
  FreshChannels w;
  const MeshAttributes& a = mesh.attributes;
  for (const CornerChannel& c : a.corner) {
    if (c.corners.rows() != mesh.F.rows()) continue;
    const AttributeRole role = c.channel.role;
    if (!w.corner_uv && role == AttributeRole::TexCoord && c.channel.width() >= 2) w.corner_uv = &c;
    if (!w.corner_normal && role == AttributeRole::Normal && c.channel.width() == 3) w.corner_normal = &c;
    if (!w.corner_color && role == AttributeRole::Color && (c.channel.width() == 3 || c.channel.width() == 4))
      w.corner_color = &c;
  }
  for (const AttributeChannel& c : a.vertex) {
    if (c.rows() != mesh.V.rows()) continue;
    if (!w.corner_uv && !w.uv && c.role == AttributeRole::TexCoord && c.width() >= 2) w.uv = &c;
    if (!w.corner_normal && !w.normal && c.role == AttributeRole::Normal && c.width() == 3) w.normal = &c;
    if (!w.corner_color && !w.color && c.role == AttributeRole::Color && (c.width() == 3 || c.width() == 4))
      w.color = &c;
  }
  for (const AttributeChannel& c : a.face)
    if (!w.material && c.name == "material" && c.width() == 1 && c.rows() == mesh.F.rows()) w.material = &c;
  return w;
}

// Appends `bytes` to buffer 0 as a new bufferView (4-byte aligned) and returns its index.
int add_view(tinygltf::Model& model, const std::string& bytes, int target) {
  std::vector<unsigned char>& data = model.buffers[0].data;
  data.resize((data.size() + 3) / 4 * 4, 0);
  tinygltf::BufferView view;
  view.buffer = 0;
  view.byteOffset = data.size();
  view.byteLength = bytes.size();
  view.target = target;
  data.insert(data.end(), bytes.begin(), bytes.end());
  model.bufferViews.push_back(view);
  return static_cast<int>(model.bufferViews.size()) - 1;
}

int add_accessor(tinygltf::Model& model, const std::string& bytes, int target, int component_type, int type,
                 std::size_t count, bool normalized) {
  tinygltf::Accessor accessor;
  accessor.bufferView = add_view(model, bytes, target);
  accessor.componentType = component_type;
  accessor.type = type;
  accessor.count = count;
  accessor.normalized = normalized;
  model.accessors.push_back(accessor);
  return static_cast<int>(model.accessors.size()) - 1;
}

// A document of one mesh: a primitive per material, vertices split wherever a corner's texture
// coordinate, normal or colour differs.
tinygltf::Model fresh_document(const Mesh& mesh) {
  const FreshChannels w = fresh_channels(mesh);
  const MeshAttributes& a = mesh.attributes;
  tinygltf::Model model;
  model.asset.version = "2.0";
  model.asset.generator = "vertexflow";
  model.buffers.emplace_back();
  tinygltf::Mesh out_mesh;

  // Unit normals for the NORMAL accessor (the validator requires them): a zero or non-finite
  // input normal is replaced by the vertex's area-weighted face normal.
  Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> vertex_normals =
      Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>::Zero(mesh.V.rows(), 3);
  for (Index f = 0; f < mesh.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) vertex_normals.row(mesh.F(f, k)) += face_normal(mesh.V, mesh.F, f).transpose();
  auto unit = [](Eigen::Vector3d n, const Eigen::Vector3d& fallback) {
    if (n.allFinite() && n.norm() > 0) return Eigen::Vector3d(n.normalized());
    if (fallback.norm() > 0) return Eigen::Vector3d(fallback.normalized());
    return Eigen::Vector3d(0, 0, 1);
  };

  std::vector<int> labels;  // material label per primitive, in first-use order
  std::vector<int> label_of_face(static_cast<std::size_t>(mesh.num_faces()), -1);
  for (Index f = 0; f < mesh.num_faces(); ++f) {
    const int label = w.material ? static_cast<int>(w.material->values(f, 0)) : -1;
    label_of_face[static_cast<std::size_t>(f)] = label;
    if (std::find(labels.begin(), labels.end(), label) == labels.end()) labels.push_back(label);
  }
  std::map<int, int> material_of_label;
  for (const int label : labels) {
    if (label < 0) continue;
    tinygltf::Material material;
    material.name = static_cast<std::size_t>(label) < a.materials.size() ? a.materials[static_cast<std::size_t>(label)]
                                                                         : fmt::format("material {}", label);
    material_of_label[label] = static_cast<int>(model.materials.size());
    model.materials.push_back(material);
  }

  const bool swap = !host_is_little_endian();
  const int color_type = [&] {
    const ScalarType t = w.corner_color ? w.corner_color->channel.type : w.color ? w.color->type : ScalarType::Float32;
    return t == ScalarType::UInt8 ? kUByte : t == ScalarType::UInt16 ? kUShort : kFloat;
  }();
  const int color_width = w.corner_color ? w.corner_color->channel.width() : w.color ? w.color->width() : 0;
  for (const int label : labels) {
    // Each distinct (vertex, uv row, normal row, colour row) is one glTF vertex.
    std::map<std::array<std::int64_t, 4>, std::uint32_t> index_of;
    std::vector<std::array<std::int64_t, 4>> keys;
    std::string indices;
    for (Index f = 0; f < mesh.num_faces(); ++f) {
      if (label_of_face[static_cast<std::size_t>(f)] != label) continue;
      for (int k = 0; k < 3; ++k) {
        const Index v = mesh.F(f, k);
        const std::array<std::int64_t, 4> key{v, w.corner_uv ? w.corner_uv->corners(f, k) : v,
                                              w.corner_normal ? w.corner_normal->corners(f, k) : v,
                                              w.corner_color ? w.corner_color->corners(f, k) : v};
        const auto [it, inserted] = index_of.try_emplace(key, static_cast<std::uint32_t>(keys.size()));
        if (inserted) keys.push_back(key);
        store_scalar<std::uint32_t>(indices, it->second, swap);
      }
    }
    tinygltf::Primitive primitive;
    primitive.mode = TINYGLTF_MODE_TRIANGLES;
    primitive.material = label >= 0 ? material_of_label[label] : -1;
    std::string bytes;
    std::array<double, 3> lo{}, hi{};
    lo.fill(std::numeric_limits<double>::infinity());
    hi.fill(-std::numeric_limits<double>::infinity());
    for (const auto& key : keys)
      for (int c = 0; c < 3; ++c) {
        const auto x = static_cast<float>(mesh.V(key[0], c));
        store_scalar<float>(bytes, x, swap);
        lo[static_cast<std::size_t>(c)] = std::min<double>(lo[static_cast<std::size_t>(c)], x);
        hi[static_cast<std::size_t>(c)] = std::max<double>(hi[static_cast<std::size_t>(c)], x);
      }
    const int position =
        add_accessor(model, bytes, TINYGLTF_TARGET_ARRAY_BUFFER, kFloat, TINYGLTF_TYPE_VEC3, keys.size(), false);
    model.accessors.back().minValues.assign(lo.begin(), lo.end());
    model.accessors.back().maxValues.assign(hi.begin(), hi.end());
    primitive.attributes["POSITION"] = position;
    if (w.corner_normal || w.normal) {
      bytes.clear();
      for (const auto& key : keys) {
        Eigen::Vector3d n = Eigen::Vector3d::Zero();
        if (w.corner_normal && key[2] >= 0) n = w.corner_normal->channel.values.row(key[2]).transpose();
        if (w.normal) n = w.normal->values.row(key[0]).transpose();
        n = unit(n, vertex_normals.row(key[0]).transpose());
        for (int c = 0; c < 3; ++c) store_scalar<float>(bytes, static_cast<float>(n[c]), swap);
      }
      primitive.attributes["NORMAL"] =
          add_accessor(model, bytes, TINYGLTF_TARGET_ARRAY_BUFFER, kFloat, TINYGLTF_TYPE_VEC3, keys.size(), false);
    }
    if (w.corner_uv || w.uv) {
      bytes.clear();
      for (const auto& key : keys)
        for (int c = 0; c < 2; ++c) {
          double x = 0;
          if (w.corner_uv && key[1] >= 0) x = w.corner_uv->channel.values(key[1], c);
          if (w.uv) x = w.uv->values(key[0], c);
          store_scalar<float>(bytes, static_cast<float>(x), swap);
        }
      primitive.attributes["TEXCOORD_0"] =
          add_accessor(model, bytes, TINYGLTF_TARGET_ARRAY_BUFFER, kFloat, TINYGLTF_TYPE_VEC2, keys.size(), false);
    }
    if (color_width > 0) {
      bytes.clear();
      for (const auto& key : keys)
        for (int c = 0; c < color_width; ++c) {
          double x = 0;
          if (w.corner_color && key[3] >= 0) x = w.corner_color->channel.values(key[3], c);
          if (w.color) x = w.color->values(key[0], c);
          if (color_type == kFloat) {
            store_scalar<float>(bytes, static_cast<float>(std::clamp(x, 0.0, 1.0)), swap);
          } else {
            const double stored = to_scalar_type(x, scalar_type_of(color_type));
            if (color_type == kUByte)
              store_scalar<std::uint8_t>(bytes, static_cast<std::uint8_t>(stored), swap);
            else
              store_scalar<std::uint16_t>(bytes, static_cast<std::uint16_t>(stored), swap);
          }
        }
      // Vertex attributes' elements start on 4-byte boundaries: pad each to a multiple of 4.
      if (color_type != kFloat && (color_width * component_size(color_type)) % 4 != 0) {
        std::string padded;
        const auto element = static_cast<std::size_t>(color_width * component_size(color_type));
        const std::size_t stride = (element + 3) / 4 * 4;
        for (std::size_t i = 0; i < keys.size(); ++i) {
          padded.append(bytes, i * element, element);
          padded.append(stride - element, '\0');
        }
        bytes = std::move(padded);
        const int accessor =
            add_accessor(model, bytes, TINYGLTF_TARGET_ARRAY_BUFFER, color_type,
                         color_width == 3 ? TINYGLTF_TYPE_VEC3 : TINYGLTF_TYPE_VEC4, keys.size(), true);
        model.bufferViews.back().byteStride = stride;
        primitive.attributes["COLOR_0"] = accessor;
      } else {
        primitive.attributes["COLOR_0"] =
            add_accessor(model, bytes, TINYGLTF_TARGET_ARRAY_BUFFER, color_type,
                         color_width == 3 ? TINYGLTF_TYPE_VEC3 : TINYGLTF_TYPE_VEC4, keys.size(), color_type != kFloat);
      }
    }
    primitive.indices = add_accessor(model, indices, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER, kUInt, TINYGLTF_TYPE_SCALAR,
                                     indices.size() / 4, false);
    out_mesh.primitives.push_back(primitive);
  }
  model.meshes.push_back(out_mesh);
  tinygltf::Node node;
  node.mesh = 0;
  model.nodes.push_back(node);
  tinygltf::Scene scene;
  scene.nodes.push_back(0);
  model.scenes.push_back(scene);
  model.defaultScene = 0;
  return model;
}

// Where each image goes: its URI in the written file ("" keeps a bufferView image as it is).
struct ImagePlan {
  const tinygltf::Model* model = nullptr;
  std::vector<std::string> uri;
};

bool write_planned_image(const std::string*, const std::string*, const tinygltf::Image* image, bool,
                         std::string* out_uri, void* user) {
  const auto* plan = static_cast<const ImagePlan*>(user);
  const auto i = static_cast<std::size_t>(image - plan->model->images.data());
  if (i >= plan->uri.size() || plan->uri[i].empty()) return false;
  *out_uri = plan->uri[i];
  return true;
}

// Serialises `model`: a GLB with every buffer and image in its binary chunk, or a .gltf whose
// buffers that were files (or a GLB's chunk) become files beside `path`, named after it, as do
// images that were files. Images keep their bytes either way.
std::string serialize(tinygltf::Model& model, const std::filesystem::path& path, bool binary) {
  const std::string name = path.string();
  const std::string stem = path.stem().string();
  std::vector<std::pair<std::string, std::string>> files;  // beside the output: name, bytes
  auto unique_name = [&](std::string file) {
    const std::string original = file;
    for (int n = 1; std::any_of(files.begin(), files.end(), [&](const auto& e) { return e.first == file; }); ++n) {
      const std::size_t dot = original.rfind('.');
      file = dot == std::string::npos ? fmt::format("{}_{}", original, n)
                                      : fmt::format("{}_{}{}", original.substr(0, dot), n, original.substr(dot));
    }
    return file;
  };
  std::vector<std::pair<std::size_t, std::string>> external_buffers;  // index, uri
  if (binary) {
    // One binary chunk holds everything (the validator warns of URIs in a GLB): buffer 0, the
    // other buffers after it, then the images that were files or data URIs.
    if (model.buffers.empty()) model.buffers.emplace_back();
    std::vector<unsigned char>& chunk = model.buffers[0].data;
    model.buffers[0].uri.clear();
    auto append = [&](const std::vector<unsigned char>& bytes) {
      chunk.resize((chunk.size() + 3) / 4 * 4, 0);
      const std::size_t offset = chunk.size();
      chunk.insert(chunk.end(), bytes.begin(), bytes.end());
      return offset;
    };
    std::vector<std::size_t> offset_of(model.buffers.size(), 0);
    for (std::size_t b = 1; b < model.buffers.size(); ++b) offset_of[b] = append(model.buffers[b].data);
    for (tinygltf::BufferView& view : model.bufferViews) {
      if (view.buffer <= 0 || static_cast<std::size_t>(view.buffer) >= model.buffers.size()) continue;
      view.byteOffset += offset_of[static_cast<std::size_t>(view.buffer)];
      view.buffer = 0;
    }
    model.buffers.resize(1);
    for (tinygltf::Image& image : model.images) {
      if (image.image.empty() || (image.uri.empty() && image.bufferView >= 0)) continue;
      tinygltf::BufferView view;
      view.buffer = 0;
      view.byteOffset = append(image.image);
      view.byteLength = image.image.size();
      model.bufferViews.push_back(view);
      image.bufferView = static_cast<int>(model.bufferViews.size()) - 1;
      image.mimeType = mime_type_of(image);
      image.uri.clear();
    }
  } else {
    for (std::size_t b = 0; b < model.buffers.size(); ++b) {
      tinygltf::Buffer& buffer = model.buffers[b];
      if (buffer.uri.rfind("data:", 0) == 0) continue;  // embedded in the input: embedded still
      const std::string file = unique_name(stem + ".bin");
      files.emplace_back(file, std::string(buffer.data.begin(), buffer.data.end()));
      external_buffers.emplace_back(b, percent_encoded(file));
      buffer.data.clear();  // not base64-encoded for nothing: the JSON is patched below
    }
  }
  ImagePlan plan;
  plan.model = &model;
  plan.uri.resize(model.images.size());
  for (std::size_t i = 0; i < model.images.size(); ++i) {
    const tinygltf::Image& image = model.images[i];
    if (image.image.empty() || (image.uri.empty() && image.bufferView >= 0)) continue;
    if (image.uri.empty()) {
      plan.uri[i] = "data:" + mime_type_of(image) + ";base64," + base64(image.image);
    } else {
      std::string last = percent_decoded(image.uri.substr(image.uri.find_last_of('/') + 1));
      for (char& c : last)
        if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '-' || c == '_')) c = '_';
      const std::string file = unique_name(stem + "_" + last);
      files.emplace_back(file, std::string(image.image.begin(), image.image.end()));
      plan.uri[i] = percent_encoded(file);
    }
  }
  tinygltf::TinyGLTF writer;
  writer.SetImageWriter(write_planned_image, &plan);
  std::ostringstream out;
  if (!writer.WriteGltfSceneToStream(&model, out, /*prettyPrint=*/!binary, binary))
    fail(name, "tinygltf could not serialise the document");
  std::string bytes = out.str();
  if (!external_buffers.empty()) {
    nlohmann::json json = nlohmann::json::parse(bytes, nullptr, /*allow_exceptions=*/false);
    if (!json.is_object() || !json.contains("buffers")) fail(name, "tinygltf wrote JSON that does not parse back");
    for (const auto& external : external_buffers) {
      const std::size_t b = external.first;
      const std::string& uri = external.second;
      nlohmann::json& buffer = json["buffers"][b];
      buffer["uri"] = uri;
      const std::string& data = std::find_if(files.begin(), files.end(), [&](const auto& e) {
                                  return percent_encoded(e.first) == uri;
                                })->second;
      buffer["byteLength"] = data.size();
    }
    bytes = json.dump(2);
  }
  for (const auto& [file, data] : files) write_text_file(path.parent_path() / file, data);
  return bytes;
}

}  // namespace

Mesh read_gltf_file(const std::filesystem::path& path, ReadReport& report, const ReadOptions& options) {
  const std::string name = path.string();
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) fail(name, "is a directory, not a mesh file");
  std::ifstream file(path, std::ios::binary);
  if (!file) fail(name, std::string("cannot open: ") + std::strerror(errno));
  const std::string bytes((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  if (file.bad()) fail(name, "read error");
  std::filesystem::path base = path.parent_path();
  if (base.empty()) base = ".";
  return build_mesh(load_document(bytes, name, base, /*read_files=*/true), name, report, options);
}

Mesh read_gltf_bytes(std::string_view bytes, const std::string& name, ReadReport& report, const ReadOptions& options) {
  return build_mesh(load_document(bytes, name, {}, /*read_files=*/false), name, report, options);
}

std::string write_gltf(const std::filesystem::path& path, const Mesh& mesh, bool binary) {
  const std::string name = path.string();
  if (mesh.num_faces() == 0) fail(name, "cannot write a glTF file without faces");
  const GltfDocument* doc = usable_document(mesh);
  tinygltf::Model model = doc ? fill_document(*doc, mesh, name) : fresh_document(mesh);
  return serialize(model, path, binary);
}

std::vector<std::string> gltf_attributes_not_written(const Mesh& mesh) {
  const MeshAttributes& a = mesh.attributes;
  std::vector<std::string> out;
  if (const GltfDocument* doc = usable_document(mesh)) {
    for (const AttributeChannel& c : a.vertex) out.push_back("vertex " + c.name);
    for (const CornerChannel& c : a.corner)
      if (!attribute_of(*doc, c.channel.name)) out.push_back("corner " + c.channel.name);
    for (const AttributeChannel& c : a.face)
      if (c.name != "primitive" && c.name != "material") out.push_back("face " + c.name);
  } else {
    if (a.gltf) out.push_back("glTF document (the mesh's vertices or faces no longer match it)");
    const FreshChannels w = fresh_channels(mesh);
    for (const AttributeChannel& c : a.vertex)
      if (&c != w.uv && &c != w.normal && &c != w.color) out.push_back("vertex " + c.name);
    for (const CornerChannel& c : a.corner)
      if (&c != w.corner_uv && &c != w.corner_normal && &c != w.corner_color) out.push_back("corner " + c.channel.name);
    for (const AttributeChannel& c : a.face)
      if (&c != w.material) out.push_back("face " + c.name);
  }
  if (!a.groups.empty()) out.push_back("group names");
  if (!a.objects.empty()) out.push_back("object names");
  if (!a.material_libraries.empty()) out.push_back("mtllib");
  return out;
}

}  // namespace vertexflow::io_detail
