// Internal to the io stage: glTF 2.0 reading and writing (io.h) through Debian's tinygltf.
// Every includer sees tinygltf's declarations with the target's TINYGLTF_* definitions
// (src/CMakeLists.txt); gltf.cpp alone compiles its implementation.
#pragma once

#include "vertexflow/io.h"

#include <tiny_gltf.h>

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace vertexflow {

/// The document a mesh was read from, and where each of the mesh's values came from in it, so
/// that the writer can put every value back (MeshAttributes::gltf).
struct GltfDocument {
  /// One kept TRIANGLES primitive, in the order the mesh concatenates them.
  struct Primitive {
    int mesh = -1;       ///< index into model.meshes
    int primitive = -1;  ///< index into model.meshes[mesh].primitives
    /// Its glTF vertices (the elements of its POSITION accessor) are rows
    /// [first_vertex, first_vertex + num_vertices) of the corner channels' tables.
    std::int64_t first_vertex = 0, num_vertices = 0;
    /// Its triangles are faces [first_face, first_face + num_faces) of the mesh.
    std::int64_t first_face = 0, num_faces = 0;
  };

  tinygltf::Model model;
  /// Where external buffers and images were read from (empty when read from memory).
  std::filesystem::path base_directory;
  /// Read from a .glb.
  bool binary = false;
  std::vector<Primitive> primitives;
  /// Per glTF vertex (all primitives' vertices, concatenated): the mesh vertex it was welded to.
  std::vector<Index> vertex_of_row;
  /// Per face, the glTF vertex of each corner, as read.
  Eigen::Matrix<std::int32_t, Eigen::Dynamic, 3, Eigen::RowMajor> face_rows;
  /// The mesh's vertex count as read.
  Index num_vertices = 0;
  /// Corner channel name -> glTF attribute ("uv" -> "TEXCOORD_0"), for the channels read.
  std::vector<std::pair<std::string, std::string>> channel_attributes;
};

namespace io_detail {

/// Reads a .gltf (with its external buffers and images, relative to `path`) or .glb file.
Mesh read_gltf_file(const std::filesystem::path& path, ReadReport& report, const ReadOptions& options);

/// Reads glTF from memory: a .glb, or a .gltf whose buffers and images are embedded (data
/// URIs; external files are refused, nothing is read from disk); `name` is used in messages.
/// GLB is recognised by its magic bytes.
Mesh read_gltf_bytes(std::string_view bytes, const std::string& name, ReadReport& report, const ReadOptions& options);

/// The bytes of `mesh` as a .glb (binary) or .gltf file; for a .gltf, the external buffers and
/// images it refers to are written beside `path` (atomically, each). Throws IoError.
std::string write_gltf(const std::filesystem::path& path, const Mesh& mesh, bool binary);

/// What write_gltf leaves out of the file (attributes_not_written for glTF).
std::vector<std::string> gltf_attributes_not_written(const Mesh& mesh);

}  // namespace io_detail
}  // namespace vertexflow
