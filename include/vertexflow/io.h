// Mesh input and output: OBJ, PLY (ASCII, binary little/big endian), OFF (ASCII, binary), STL
// (ASCII, binary), each optionally gzip-compressed on input and output (`NAME.EXT.gz`), and
// glTF 2.0 (`.gltf` with its external buffers and images, `.glb`; not gzip-compressed).
//
// glTF: the triangle primitives of every mesh of the document (indexed or not; strips and fans
// are named as not kept), in the meshes' own coordinates (node transforms are not applied),
// their vertices welded where their positions are bitwise equal within a glTF mesh (glTF
// splits a vertex wherever an attribute differs) so that the mesh is connected for the flow.
// Each primitive's vertex attributes (NORMAL, TEXCOORD_n, COLOR_0, JOINTS_0, WEIGHTS_0, TANGENT)
// become corner channels whose rows are the glTF vertices, so writing splits them again exactly
// where the file did; face channels "primitive" and "material" say where each face came from.
// The face list is always kept as the file has it (ReadOptions::keep_face_list is implied).
// Writing a mesh read from glTF writes the input document (MeshAttributes::gltf) with only
// those accessors' values (and the indices, where edge flips changed faces) replaced, and only
// where they changed: materials, textures, images, nodes, skins and animations pass through
// (morph targets are not moved with the vertices). A .glb holds every buffer and image in its
// binary chunk; a .gltf's external files are written beside it as STEM.bin and STEM_IMAGE, so
// that they never overwrite the input's. Any other mesh is written as a new document with one
// primitive per material.

#pragma once

#include "vertexflow/mesh.h"

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace vertexflow {

/// Thrown by every reader and writer. what() is "FILE: problem" on one line.
class IoError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

enum class MeshFormat { Obj, Ply, Off, Stl, Gltf };

/// Most comment lines a reader keeps (the first ones; the rest are skipped).
inline constexpr std::size_t kMaxCommentLines = 256;
/// Most bytes of one comment line a reader keeps (the rest of the line is skipped).
inline constexpr std::size_t kMaxCommentBytes = 1024;

/// "OBJ", "PLY", "OFF", "STL" or "glTF".
const char* format_name(MeshFormat format);

/// The extension of `path` with its dot, lowercase (".ply"); empty when it has none.
std::string lowercase_extension(const std::filesystem::path& path);

/// File format from the extension (case-insensitive, a trailing ".gz" ignored).
/// Throws IoError for an unknown extension.
MeshFormat format_from_path(const std::filesystem::path& path);

/// Whether the path has a mesh extension format_from_path accepts.
bool is_mesh_path(const std::filesystem::path& path);

/// Whether the path ends in ".gz" (case-insensitive).
bool is_gzip_path(const std::filesystem::path& path);

/// 32, or the environment variable VERTEXFLOW_MAX_INFLATE_RATIO when it holds a positive number
/// (read once, at the first call).
double default_max_inflate_ratio();

struct ReadOptions {
  /// gzip input is inflated as the parser reads it, and may inflate to at most
  /// max(inflate_floor_bytes, max_inflate_ratio x its compressed size) bytes; more is an error
  /// (a decompression bomb). Real meshes compress 1-12 times (the bundled ones, gzip -9), so
  /// the default ratio leaves room; the floor lets small files of any ratio through.
  double max_inflate_ratio = default_max_inflate_ratio();
  std::uint64_t inflate_floor_bytes = std::uint64_t{64} << 20;
  /// Remove faces whose area is below kDegenerateAreaRelative * diagonal^2.
  bool remove_zero_area_faces = true;
  /// Keep the file's face list and vertex list as they are: no face or vertex is removed
  /// (zero-area, repeated-index and duplicate faces and unreferenced vertices stay, counted in
  /// ReadReport's *_kept), so that anything indexed by face or vertex still lines up. Polygons
  /// are still triangulated, in place. `enhance` reads this way and holds the vertices of such
  /// faces (enhance.h).
  bool keep_face_list = false;
};

/// What reading had to change to produce a clean triangle mesh. Every count is also a warning.
struct ReadReport {
  /// The format read: the extension's, unless the content is beyond doubt another format's
  /// (a PLY header in a file named .obj, a binary STL by its size), which then wins.
  MeshFormat format = MeshFormat::Obj;
  bool format_differs_from_extension = false;
  bool binary = false;
  bool gzip = false;
  /// ASCII PLY lines with more values than their element declares (a writer bug): the
  /// declared values are read, the extra ones ignored.
  std::int64_t ply_extra_values_lines = 0;
  /// Polygons with more than three vertices that were triangulated.
  std::int64_t polygons_triangulated = 0;
  /// Polygons that could not be triangulated in their plane (self-intersecting or folded) and
  /// were fanned from their first vertex instead.
  std::int64_t polygons_fanned = 0;
  /// Vertices merged into an earlier identical one (STL only).
  std::int64_t vertices_welded = 0;
  std::int64_t unreferenced_vertices_removed = 0;
  /// Faces with fewer than three distinct vertex indices.
  std::int64_t repeated_index_faces_removed = 0;
  std::int64_t duplicate_faces_removed = 0;
  std::int64_t zero_area_faces_removed = 0;
  /// Triangles read from PLY `tristrips` elements (strips with -1 restarts; the strips'
  /// degenerate stitching triangles are not faces and are skipped).
  std::int64_t strip_triangles = 0;
  /// With ReadOptions::keep_face_list: the faces and vertices that would have been removed.
  std::int64_t degenerate_faces_kept = 0;
  std::int64_t duplicate_faces_kept = 0;
  std::int64_t unreferenced_vertices_kept = 0;
  /// What the file holds that the mesh does not keep (attributes.h keeps every vertex and face
  /// property and OBJ's texture coordinates, normals, materials and groups), one entry each with
  /// its count, e.g. "PLY element 'edge' (12)", "OBJ lines l (3)", in the order first met.
  std::vector<std::string> not_kept;

  /// One human-readable line per non-zero count, e.g. "3 duplicate faces removed", and one line
  /// naming what was not kept.
  [[nodiscard]] std::vector<std::string> warnings() const;
};

/// Reads a mesh, choosing the format from the extension unless the content shows another
/// (ReadReport::format). Throws IoError, also when memory runs out.
Mesh read_mesh(const std::filesystem::path& path, ReadReport* report = nullptr, const ReadOptions& options = {});

/// Reads a mesh from bytes already in memory (used by the fuzzers and by read_mesh).
/// `name` is used in error messages only. gzip data is recognised by its magic bytes.
Mesh read_mesh_from_memory(std::string_view bytes, MeshFormat format, const std::string& name,
                           ReadReport* report = nullptr, const ReadOptions& options = {});

enum class PlyEncoding { BinaryLittleEndian, BinaryBigEndian, Ascii };

struct WriteOptions {
  /// PLY encoding; binary little-endian by default (compact, fast, read by every tool).
  PlyEncoding ply_encoding = PlyEncoding::BinaryLittleEndian;
  /// PLY vertex coordinates as float64 (exact round trip) or float32 (half the size).
  bool ply_double_precision = true;
  /// STL: binary by default (float32 coordinates, as the format defines), ASCII when false.
  bool stl_binary = true;
  /// OFF: ASCII by default; binary OFF (big-endian float32) when true.
  bool off_binary = false;
  /// Write per-vertex colours where the format can carry them (PLY, OFF as COFF).
  bool write_colors = true;
  /// Write the vertex channels other than colours (PLY; OBJ's per-vertex texture coordinates
  /// and normals).
  bool write_vertex_properties = true;
  /// Write corner and face channels, materials, groups and material libraries (OBJ, PLY).
  bool write_attributes = true;
};

/// Writes a mesh, format chosen by extension (".gz" compresses). Mesh::comments are written
/// after the writer's stamp, one per line, as PLY `comment` lines, OBJ `#` lines and, in ASCII
/// OFF, `#` lines after the keyword line (binary OFF, whose header is one line, and STL carry
/// none); control characters in them become '?'. The file is written to a
/// temporary file in the same directory and renamed into place, so `path` is either left as it
/// was or holds the complete new mesh. Throws IoError.
///
/// On Linux the temporary file is unnamed (O_TMPFILE) until the moment it is renamed into
/// place, so a process killed mid-write (even by SIGKILL) leaves nothing behind. Where the file
/// system lacks O_TMPFILE (or the environment variable VERTEXFLOW_NO_O_TMPFILE is set, for
/// tests) it is a hidden named file `.NAME.tmp-NNN`, which a handler installed on first use
/// removes on SIGINT and SIGTERM before the process dies of the signal; the handler is installed
/// only over the default disposition, never over a program's own handler or SIG_IGN.
void write_mesh(const std::filesystem::path& path, const Mesh& mesh, const WriteOptions& options = {});

/// What write_mesh would leave out of a file of `format`, one entry per channel ("corner
/// normal", "face quality", "material names"): STL holds none, OFF one colour, OBJ texture
/// coordinates, normals, materials, groups, objects and smoothing groups, PLY every vertex and
/// face channel and one two-component texture coordinate per corner. Empty when nothing is lost.
std::vector<std::string> attributes_not_written(const Mesh& mesh, MeshFormat format, const WriteOptions& options = {});

/// The one warning every front end gives for attributes_not_written: "FORMAT cannot hold, so it
/// does not get: a, b" (format_name), or empty when nothing is lost.
std::string attributes_not_written_warning(const Mesh& mesh, MeshFormat format, const WriteOptions& options = {});

/// Writes `text` to `path` atomically (temporary file beside it, then rename). Throws IoError.
void write_text_file(const std::filesystem::path& path, std::string_view text);

/// Throws IoError unless a file can be written at `output` now: it is not a directory and its
/// directory accepts a new file (probed by creating and discarding the temporary file that
/// write_mesh would start with). For checking every output of a command before any work.
void check_output_writable(const std::filesystem::path& output);

/// Throws IoError unless `output` is safe to write while `input` is being processed: it must
/// not be the same file as the input (unless `force`), must not be a directory and, when
/// `mesh_output`, must have a mesh extension.
void check_output_path(const std::filesystem::path& input, const std::filesystem::path& output, bool force,
                       bool mesh_output = true);

}  // namespace vertexflow
