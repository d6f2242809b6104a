// What a mesh carries besides its positions and faces: per-vertex, per-corner and per-face
// channels (texture coordinates, normals, colours, labels, skin weights, any PLY property), and
// the file-level names they refer to (OBJ materials, groups, material libraries). Readers fill
// them, writers write them back with the same names, types, order and values, and `enhance`
// re-samples them where vertices move (docs/attributes.md).
//
// Conventions
// - Every value is held as a double, whatever its type in the file: doubles hold every value of
//   every ScalarType exactly (32-bit integers and float32 included), so a read followed by a
//   write reproduces the file's values bit for bit. `type` is the type the file had and a
//   writer writes.
// - A channel's rows are aligned with what it is attached to: vertices (rows of Mesh::V), faces
//   (rows of Mesh::F) or, for a CornerChannel, its own table of distinct values that the
//   corners index (OBJ `vt`/`vn`: a seam is where a vertex's corners index different rows).
// - Labels (materials, groups, OBJ objects, smoothing groups) are Int32 face channels whose
//   values index the name tables below (materials, groups, objects), -1 for none; OBJ
//   smoothing groups are the group number itself, 0 for off.
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace vertexflow {

/// The scalar type a channel has in its file (PLY's eight types; OBJ's are Float64).
enum class ScalarType : std::uint8_t { Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32, Float64 };

/// What a channel means, which decides how it follows a moved vertex (enhance.h).
enum class AttributeRole : std::uint8_t {
  Generic,   ///< floats: interpolated at the vertex's new place on the input surface
  Color,     ///< interpolated, then rounded and clamped to an integer type's range
  TexCoord,  ///< interpolated in the vertex's own chart (never across a seam)
  Normal,    ///< recomputed from the moved geometry (unit length, outward as the faces are)
  Label,     ///< kept as it is (material, group, bone index, any integer property)
  Weights,   ///< skin weights: interpolated, then renormalised to sum 1
};

/// "int8", "uint8", ..., "float64".
const char* scalar_type_name(ScalarType type);
/// Whether the type is one of the six integer types.
bool is_integer_type(ScalarType type);
/// Rounds and clamps `value` to what `type` can hold (integers), or to float precision
/// (Float32); Float64 values pass unchanged. What a writer stores for a value.
double to_scalar_type(double value, ScalarType type);
/// "generic", "color", "texcoord", "normal", "label", "weights".
const char* attribute_role_name(AttributeRole role);

/// A named channel of one or more components.
struct AttributeChannel {
  /// The channel's name: "color", "normal", "uv", "material", or a PLY property's own name.
  std::string name;
  /// The file's component names, in file order ({"red", "green", "blue"}, {"s", "t"}, {"x"}).
  std::vector<std::string> components;
  ScalarType type = ScalarType::Float64;
  AttributeRole role = AttributeRole::Generic;
  /// rows x components.size(), row-major.
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> values;

  [[nodiscard]] Eigen::Index rows() const { return values.rows(); }
  [[nodiscard]] int width() const { return static_cast<int>(components.size()); }
};

/// A channel whose values belong to face corners (wedges): OBJ `vt` and `vn` with their own
/// indices, PLY face `texcoord` lists. `corners(f, k)` is the row of `channel.values` that
/// corner k of face f uses, -1 where the corner has none (an OBJ `f 1 2/3 4`).
struct CornerChannel {
  AttributeChannel channel;
  Eigen::Matrix<std::int32_t, Eigen::Dynamic, 3, Eigen::RowMajor> corners;
};

/// The glTF document a mesh was read from (opaque here; src/io/gltf.h): its materials, textures,
/// images, nodes, skins and animations, written back around the mesh's new accessors.
struct GltfDocument;

/// Everything a mesh carries besides V and F.
struct MeshAttributes {
  /// One row per vertex; in a PLY, the vertex properties after x, y, z, in file order.
  std::vector<AttributeChannel> vertex;
  /// Per face corner.
  std::vector<CornerChannel> corner;
  /// One row per face; PLY face properties other than the indices, OBJ `usemtl`, `g`, `o`, `s`.
  std::vector<AttributeChannel> face;
  /// Names the label channels index (OBJ `usemtl`, `g` and `o` names), in first-use order.
  std::vector<std::string> materials, groups, objects;
  /// OBJ `mtllib` file names, in file order.
  std::vector<std::string> material_libraries;
  /// Set by the glTF reader: the document, which the glTF writer fills with the mesh's values
  /// (io.h). Shared, never modified: copies of a mesh share it.
  std::shared_ptr<const GltfDocument> gltf;

  [[nodiscard]] bool empty() const {
    return vertex.empty() && corner.empty() && face.empty() && material_libraries.empty();
  }
  /// The vertex channel called `name`, or nullptr.
  [[nodiscard]] const AttributeChannel* find_vertex(std::string_view name) const;
  [[nodiscard]] AttributeChannel* find_vertex(std::string_view name);
  /// The first vertex channel with role `role`, or nullptr.
  [[nodiscard]] const AttributeChannel* find_vertex(AttributeRole role) const;
  /// The face channel called `name`, or nullptr.
  [[nodiscard]] const AttributeChannel* find_face(std::string_view name) const;
  /// The corner channel called `name`, or nullptr.
  [[nodiscard]] const CornerChannel* find_corner(std::string_view name) const;

  /// Throws std::invalid_argument naming the first channel whose size disagrees with
  /// `num_vertices`/`num_faces`, whose width differs from its component names, whose corner
  /// index is out of its table, or whose label indexes past its name table.
  void validate(std::int64_t num_vertices, std::int64_t num_faces) const;
};

}  // namespace vertexflow
