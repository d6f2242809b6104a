// vertexflow: feature enhancement of triangle meshes by vertex flow.
//
// The mesh type every stage of the library works on, and the conventions the whole library
// shares. They are stated once, here.
//
// Conventions
// - Positions are double precision, one row per vertex (x, y, z), in the input's own units;
//   nothing in the library rescales a mesh the caller gives it unless a function says so.
// - Triangles are rows of three 0-based vertex indices. The orientation (i, j, k) defines the
//   face normal (v_j - v_i) x (v_k - v_i): counter-clockwise seen from the side the normal
//   points to. For a closed mesh with consistent orientation the normals point outwards when
//   the signed volume is positive.
// - Both matrices are row-major so a vertex or face is contiguous in memory; they interoperate
//   with libigl-style V/F (Eigen::MatrixXd / Eigen::MatrixXi) by plain assignment.
// - Per-vertex data (properties, colours) is aligned with the rows of V, per-face data with the
//   rows of F (attributes.h).
#pragma once

#include "vertexflow/attributes.h"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace vertexflow {

/// Vertex and face index type. 32 bits, as in libigl; meshes are limited to 2^31 - 1 elements.
using Index = std::int32_t;

/// Vertex positions: #V x 3, row-major.
using Vertices = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;

/// Triangles: #F x 3 vertex indices, row-major.
using Faces = Eigen::Matrix<Index, Eigen::Dynamic, 3, Eigen::RowMajor>;

/// 8-bit RGB colours, one row per vertex.
using Colors = Eigen::Matrix<std::uint8_t, Eigen::Dynamic, 3, Eigen::RowMajor>;

/// Relative area below which a triangle counts as degenerate: area < kDegenerateAreaRelative *
/// (bounding-box diagonal)^2. The same bound is used when reading (such faces are removed) and
/// when measuring a result (docs/metrics.md, "degenerate faces").
inline constexpr double kDegenerateAreaRelative = 1e-12;

/// That bound for a mesh whose bounding-box diagonal is `diagonal`: a face with a smaller area
/// is degenerate.
inline double degenerate_area_bound(double diagonal) {
  return kDegenerateAreaRelative * diagonal * diagonal;
}

/// A triangle mesh with what it carries: texture coordinates, normals, colours, labels and any
/// other property (attributes.h), and comment lines.
struct Mesh {
  Vertices V;
  Faces F;
  /// Per-vertex, per-corner and per-face channels and the names they index.
  MeshAttributes attributes;
  /// Free-text comment lines, in file order, without the comment marker: PLY `comment` lines,
  /// OBJ and OFF `#` lines (io.h says which, and how many are kept). `vertexflow enhance` keeps
  /// its input's and adds one recording how the vertices were placed (provenance.h). Each is
  /// one line: writers replace control characters (a newline would end the comment early).
  std::vector<std::string> comments;

  [[nodiscard]] Index num_vertices() const { return static_cast<Index>(V.rows()); }
  [[nodiscard]] Index num_faces() const { return static_cast<Index>(F.rows()); }

  /// Adds or replaces the one-component Float64 vertex channel called `name` (written to PLY as
  /// `property double NAME`). `values.size()` must equal num_vertices(); throws
  /// std::invalid_argument otherwise.
  void set_vertex_property(std::string name, const Eigen::VectorXd& values);
  /// The one-component vertex channel called `name` as a column, or nullptr.
  [[nodiscard]] const AttributeChannel* find_vertex_property(std::string_view name) const;
  /// Adds or replaces the vertex channel "color" (role Color, uint8 red green blue).
  void set_vertex_colors(const Colors& colors);
  /// The first Color vertex channel as 8-bit RGB (float colours in [0, 1] are scaled by 255), or
  /// an empty matrix.
  [[nodiscard]] Colors vertex_colors() const;
};

/// Axis-aligned bounding box of the vertices. For an empty mesh min = max = 0.
struct BoundingBox {
  Eigen::Vector3d min = Eigen::Vector3d::Zero();
  Eigen::Vector3d max = Eigen::Vector3d::Zero();
  [[nodiscard]] double diagonal() const { return (max - min).norm(); }
};

/// Bounding box of V's rows.
BoundingBox bounding_box(const Vertices& V);

/// Unnormalised normal of triangle f: (v1 - v0) x (v2 - v0), length twice the area.
Eigen::Vector3d face_normal(const Vertices& V, const Faces& F, Index f);

/// Faces whose normal turned by more than 90 degrees from `before` to `after` (same faces).
std::vector<Index> flipped_faces(const Vertices& before, const Vertices& after, const Faces& F);

/// Faces with area below kDegenerateAreaRelative * (bounding-box diagonal of V)^2.
std::vector<Index> degenerate_faces(const Vertices& V, const Faces& F);

/// Area of triangle f.
double face_area(const Vertices& V, const Faces& F, Index f);

/// Signed volume enclosed by the faces, sum of v0 . (v1 x v2) / 6 (divergence theorem):
/// positive for a closed mesh with outward orientation; for an open mesh, the volume of the
/// cone from the origin (not translation-invariant).
double signed_volume(const Vertices& V, const Faces& F);

}  // namespace vertexflow
