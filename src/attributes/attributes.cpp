// The attribute data model (include/vertexflow/attributes.h) and Mesh's accessors to it.
#include "vertexflow/attributes.h"
#include "vertexflow/mesh.h"

#include <fmt/format.h>

#include <cmath>
#include <limits>
#include <stdexcept>

namespace vertexflow {

const char* scalar_type_name(ScalarType type) {
  switch (type) {
    case ScalarType::Int8:
      return "int8";
    case ScalarType::UInt8:
      return "uint8";
    case ScalarType::Int16:
      return "int16";
    case ScalarType::UInt16:
      return "uint16";
    case ScalarType::Int32:
      return "int32";
    case ScalarType::UInt32:
      return "uint32";
    case ScalarType::Float32:
      return "float32";
    case ScalarType::Float64:
      return "float64";
  }
  return "?";
}

bool is_integer_type(ScalarType type) {
  return type != ScalarType::Float32 && type != ScalarType::Float64;
}

namespace {

template <class T>
double clamp_round(double value) {
  if (std::isnan(value)) return 0;
  const double rounded = std::nearbyint(value);
  return std::min<double>(std::max<double>(rounded, std::numeric_limits<T>::lowest()), std::numeric_limits<T>::max());
}

}  // namespace

double to_scalar_type(double value, ScalarType type) {
  switch (type) {
    case ScalarType::Int8:
      return clamp_round<std::int8_t>(value);
    case ScalarType::UInt8:
      return clamp_round<std::uint8_t>(value);
    case ScalarType::Int16:
      return clamp_round<std::int16_t>(value);
    case ScalarType::UInt16:
      return clamp_round<std::uint16_t>(value);
    case ScalarType::Int32:
      return clamp_round<std::int32_t>(value);
    case ScalarType::UInt32:
      return clamp_round<std::uint32_t>(value);
    case ScalarType::Float32:
      return static_cast<double>(static_cast<float>(value));
    case ScalarType::Float64:
      return value;
  }
  return value;
}

const char* attribute_role_name(AttributeRole role) {
  switch (role) {
    case AttributeRole::Generic:
      return "generic";
    case AttributeRole::Color:
      return "color";
    case AttributeRole::TexCoord:
      return "texcoord";
    case AttributeRole::Normal:
      return "normal";
    case AttributeRole::Label:
      return "label";
    case AttributeRole::Weights:
      return "weights";
  }
  return "?";
}

namespace {

template <class Channels>
auto* find_named(Channels& channels, std::string_view name) {
  for (auto& c : channels)
    if (c.name == name) return &c;
  return static_cast<decltype(&channels.front())>(nullptr);
}

}  // namespace

const AttributeChannel* MeshAttributes::find_vertex(std::string_view name) const {
  return find_named(vertex, name);
}
AttributeChannel* MeshAttributes::find_vertex(std::string_view name) {
  return find_named(vertex, name);
}
const AttributeChannel* MeshAttributes::find_vertex(AttributeRole role) const {
  for (const AttributeChannel& c : vertex)
    if (c.role == role) return &c;
  return nullptr;
}
const AttributeChannel* MeshAttributes::find_face(std::string_view name) const {
  return find_named(face, name);
}
const CornerChannel* MeshAttributes::find_corner(std::string_view name) const {
  for (const CornerChannel& c : corner)
    if (c.channel.name == name) return &c;
  return nullptr;
}

void MeshAttributes::validate(std::int64_t num_vertices, std::int64_t num_faces) const {
  auto fail = [](const std::string& message) { throw std::invalid_argument("attributes: " + message); };
  auto check = [&](const AttributeChannel& c, const char* kind, std::int64_t rows) {
    if (c.values.cols() != c.width())
      fail(fmt::format("{} channel '{}' has {} columns for {} component names", kind, c.name, c.values.cols(),
                       c.width()));
    if (rows >= 0 && c.values.rows() != rows)
      fail(fmt::format("{} channel '{}' has {} rows for {} {}", kind, c.name, c.values.rows(), rows,
                       std::string(kind) == "vertex" ? "vertices" : "faces"));
  };
  for (const AttributeChannel& c : vertex) check(c, "vertex", num_vertices);
  for (const AttributeChannel& c : face) {
    check(c, "face", num_faces);
    const std::vector<std::string>* names = c.name == "material" ? &materials
                                            : c.name == "group"  ? &groups
                                            : c.name == "object" ? &objects
                                                                 : nullptr;
    // Labels index the names only where there are names (an OBJ's; a PLY `material` property is
    // a number of its own).
    if (names && !names->empty() && c.values.size() > 0 &&
        (c.values.maxCoeff() >= static_cast<double>(names->size()) || c.values.minCoeff() < -1))
      fail(fmt::format("face channel '{}' has a label outside -1..{}", c.name, names->size() - 1));
  }
  for (const CornerChannel& c : corner) {
    check(c.channel, "corner", -1);
    if (c.corners.rows() != num_faces)
      fail(fmt::format("corner channel '{}' has {} rows of corners for {} faces", c.channel.name, c.corners.rows(),
                       num_faces));
    if (c.corners.size() > 0 && (c.corners.minCoeff() < -1 || c.corners.maxCoeff() >= c.channel.values.rows()))
      fail(fmt::format("corner channel '{}' indexes outside its {} values", c.channel.name, c.channel.values.rows()));
  }
}

void Mesh::set_vertex_property(std::string name, const Eigen::VectorXd& values) {
  if (values.size() != V.rows())
    throw std::invalid_argument("vertex property '" + name + "' has " + std::to_string(values.size()) + " values for " +
                                std::to_string(V.rows()) + " vertices");
  AttributeChannel* channel = attributes.find_vertex(name);
  if (channel == nullptr) channel = &attributes.vertex.emplace_back();
  channel->name = name;
  channel->components = {std::move(name)};
  channel->type = ScalarType::Float64;
  channel->role = AttributeRole::Generic;
  channel->values = values;
}

const AttributeChannel* Mesh::find_vertex_property(std::string_view name) const {
  const AttributeChannel* channel = attributes.find_vertex(name);
  return channel != nullptr && channel->width() == 1 ? channel : nullptr;
}

void Mesh::set_vertex_colors(const Colors& colors) {
  if (colors.rows() != V.rows())
    throw std::invalid_argument(fmt::format("{} colours for {} vertices", colors.rows(), V.rows()));
  AttributeChannel* channel = nullptr;
  for (AttributeChannel& c : attributes.vertex)
    if (c.role == AttributeRole::Color) channel = &c;
  if (channel == nullptr) channel = &attributes.vertex.emplace_back();
  channel->name = "color";
  channel->components = {"red", "green", "blue"};
  channel->type = ScalarType::UInt8;
  channel->role = AttributeRole::Color;
  channel->values = colors.cast<double>();
}

Colors Mesh::vertex_colors() const {
  const AttributeChannel* channel = attributes.find_vertex(AttributeRole::Color);
  if (channel == nullptr || channel->width() < 3 || channel->rows() != V.rows()) return Colors();
  const double scale = is_integer_type(channel->type) ? 1.0 : 255.0;
  Colors colors(channel->rows(), 3);
  for (Eigen::Index v = 0; v < channel->rows(); ++v)
    for (int c = 0; c < 3; ++c)
      colors(v, c) = static_cast<std::uint8_t>(to_scalar_type(scale * channel->values(v, c), ScalarType::UInt8));
  return colors;
}

}  // namespace vertexflow
