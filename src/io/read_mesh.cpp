// Reading: load the bytes (decompressing gzip), dispatch to a format parser, then turn the
// polygon soup into a clean triangle mesh.
#include "gltf.h"
#include "io_internal.h"
#include "mesh/duplicate_faces.h"
#include "mesh/position_key.h"

#include <zlib.h>

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/stat.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <unistd.h>
#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <iterator>
#include <memory>
#include <optional>
#include <unordered_map>

namespace vertexflow {
namespace io_detail {

void fail(const std::string& name, const std::string& message) {
  // A file name may contain control characters (even a newline); the message stays one line.
  std::string printable_name = name;
  for (char& c : printable_name) {
    if (static_cast<unsigned char>(c) < 32) c = '?';
  }
  throw IoError(printable_name + ": " + message);
}

void TextScanner::error(const std::string& message) const {
  const std::size_t end = std::min(pos_, text_.size());
  const std::uint64_t line =
      1 + (source_ ? source_->newlines_dropped() : 0) +
      static_cast<std::uint64_t>(std::count(text_.begin(), text_.begin() + static_cast<std::ptrdiff_t>(end), '\n'));
  fail(name_, fmt::format("line {}: {}", line - std::min(lines_back_, line - 1), message));
}

void add_comment(std::vector<std::string>& comments, std::string_view line) {
  if (comments.size() >= kMaxCommentLines) return;
  line = line.substr(0, line.find('\n'));
  const auto blank = [](char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; };
  while (!line.empty() && blank(line.front())) line.remove_prefix(1);
  line = line.substr(0, kMaxCommentBytes);
  while (!line.empty() && blank(line.back())) line.remove_suffix(1);
  if (line.empty() || line == kWriterStamp) return;
  std::string& text = comments.emplace_back(line);
  for (char& c : text) {
    if (static_cast<unsigned char>(c) < 32 || c == 127) c = '?';
  }
}

std::string TextScanner::printable(std::string_view tok) {
  std::string out;
  for (const char c : tok.substr(0, 40)) {
    out.push_back(static_cast<unsigned char>(c) < 32 || static_cast<unsigned char>(c) > 126 ? '?' : c);
  }
  if (tok.size() > 40) out += "...";
  return out;
}

namespace {

constexpr double kMinDiagonal = 1e-60;
constexpr double kMaxDiagonal = 1e60;

// The bytes of a file, in a buffer that is not zero-filled first (read() overwrites it).
struct FileBytes {
  std::unique_ptr<char[]> data;
  std::size_t size = 0;
  [[nodiscard]] std::string_view view() const { return {data.get(), size}; }
};

// Closes a file descriptor on every way out of a scope.
struct FdGuard {
  int fd;
  ~FdGuard() {
    if (fd >= 0) ::close(fd);
  }
};

FileBytes read_file_bytes(const std::filesystem::path& path) {
  const std::string name = path.string();
  // O_NONBLOCK: opening a FIFO (e.g. "pipe.obj") for reading would otherwise block until a
  // writer appears; this way it opens at once and is refused below as not a regular file.
  // It has no effect on reads from regular files.
  const FdGuard file{::open(name.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK)};
  if (file.fd < 0) fail(name, std::string("cannot open: ") + std::strerror(errno));
  struct stat st {};
  if (::fstat(file.fd, &st) != 0) fail(name, std::string("cannot stat: ") + std::strerror(errno));
  if (S_ISDIR(st.st_mode)) fail(name, "is a directory, not a mesh file");
  if (!S_ISREG(st.st_mode)) fail(name, "is not a regular file");
  FileBytes bytes;
  bytes.size = static_cast<std::size_t>(st.st_size);
  bytes.data.reset(new char[std::max<std::size_t>(bytes.size, 1)]);
  std::size_t done = 0;
  while (done < bytes.size) {
    const ssize_t n = ::read(file.fd, bytes.data.get() + done, bytes.size - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      fail(name, std::string("read error: ") + std::strerror(errno));
    }
    if (n == 0) break;  // the file shrank while we read it
    done += static_cast<std::size_t>(n);
  }
  bytes.size = done;
  return bytes;
}

// Merges vertices with identical coordinates (STL facets). Keeps first-occurrence order.
void weld_identical_vertices(PolygonSoup& soup, ReadReport& report) {
  const std::size_t nv = static_cast<std::size_t>(soup.num_vertices());
  std::unordered_map<PositionKey, Index, PositionKeyHash> index_of;
  index_of.reserve(nv / 4 + 16);
  std::vector<Index> remap(nv);
  std::vector<double> welded;
  welded.reserve(soup.xyz.size() / 4 + 16);
  for (std::size_t v = 0; v < nv; ++v) {
    const auto [it, inserted] =
        index_of.try_emplace(position_key(soup.xyz.data() + 3 * v), static_cast<Index>(welded.size() / 3));
    if (inserted)
      welded.insert(welded.end(), soup.xyz.begin() + 3 * static_cast<std::ptrdiff_t>(v),
                    soup.xyz.begin() + 3 * static_cast<std::ptrdiff_t>(v) + 3);
    remap[v] = it->second;
  }
  for (auto& c : soup.corners) c = remap[static_cast<std::size_t>(c)];
  report.vertices_welded += static_cast<std::int64_t>(nv - welded.size() / 3);
  soup.xyz = std::move(welded);
}

}  // namespace

Mesh soup_to_mesh(PolygonSoup&& soup, const std::string& name, ReadReport& report, const ReadOptions& options) {
  const std::int64_t nv64 = soup.num_vertices();
  if (nv64 == 0) fail(name, "the file contains no vertices");
  if (soup.num_polygons() == 0) fail(name, "the file contains no faces");
  if (nv64 > std::numeric_limits<Index>::max())
    fail(name, fmt::format("{} vertices exceed the supported maximum of 2^31-1", nv64));
  if (static_cast<std::int64_t>(soup.corners.size()) > std::numeric_limits<Index>::max())
    fail(name, fmt::format("{} face corners exceed the supported maximum of 2^31-1", soup.corners.size()));
  for (std::size_t i = 0; i < soup.xyz.size(); ++i) {
    if (!std::isfinite(soup.xyz[i]))
      fail(name, fmt::format("vertex {} has a non-finite coordinate ({})", i / 3, soup.xyz[i]));
  }
  for (std::int64_t p = 0; p < soup.num_polygons(); ++p) {
    const auto size = soup.offsets[static_cast<std::size_t>(p) + 1] - soup.offsets[static_cast<std::size_t>(p)];
    if (size < 3) fail(name, fmt::format("face {} has {} vertices; a face needs at least 3", p, size));
    for (auto c = soup.offsets[static_cast<std::size_t>(p)]; c < soup.offsets[static_cast<std::size_t>(p) + 1]; ++c) {
      const Index v = soup.corners[static_cast<std::size_t>(c)];
      // In 64 bits: the file's own numbering of vertex 2^31-1 does not fit an Index.
      if (v < 0 || v >= nv64)
        fail(name, fmt::format("face {} references vertex {}, but the file has {} vertices (valid: {}..{})", p,
                               std::int64_t{v} + soup.index_base, nv64, soup.index_base, nv64 - 1 + soup.index_base));
    }
  }
  if (soup.weld_vertices) weld_identical_vertices(soup, report);
  const Index nv = static_cast<Index>(soup.num_vertices());

  // Triangulate, dropping faces with fewer than three distinct vertices. A file of triangles
  // only (the common case) hands its corner list over as it is. Where faces carry data (face
  // and corner channels), each triangle's polygon and corners are tracked so that it takes
  // theirs; a file of triangles only needs no tracking (triangle t is polygon t).
  for (auto& rows : soup.corner_rows) rows.resize(soup.corners.size(), -1);
  const bool track = !soup.attributes.corner.empty() || !soup.attributes.face.empty();
  std::vector<Index> tris;
  std::vector<Index> polygon;
  std::vector<std::int64_t> polygon_corner;           // soup corner of each entry of `polygon`
  std::vector<std::int64_t> tri_corner, tri_polygon;  // per triangle corner, per triangle
  EdgeSet edges;                                      // filled only when the file has polygons
  const bool has_polygons = soup.corners.size() != 3 * static_cast<std::size_t>(soup.num_polygons());
  const bool tracked = track && has_polygons;
  auto source_of = [&](std::size_t t) { return tracked ? tri_polygon[t] : static_cast<std::int64_t>(t); };
  auto corner_of = [&](std::size_t t, int k) {
    return tracked ? tri_corner[3 * t + static_cast<std::size_t>(k)] : static_cast<std::int64_t>(3 * t) + k;
  };
  if (!has_polygons) {
    tris = std::move(soup.corners);
    soup.offsets = {0};  // nothing left for the polygon loop below
  } else {
    tris.reserve(soup.corners.size());
    for (std::int64_t p = 0; p < soup.num_polygons(); ++p) {
      const auto begin = soup.offsets[static_cast<std::size_t>(p)], end = soup.offsets[static_cast<std::size_t>(p) + 1];
      for (auto c = begin; c < end; ++c)
        edges.insert(edge_key(soup.corners[static_cast<std::size_t>(c)],
                              soup.corners[static_cast<std::size_t>(c + 1 < end ? c + 1 : begin)]));
    }
  }
  // Records the source of the triangles appended to `tris` since `first` (a multiple of 3).
  auto track_new = [&](std::size_t first, std::int64_t p) {
    if (!tracked) return;
    for (std::size_t i = first; i < tris.size(); ++i) {
      std::size_t at = 0;
      while (at + 1 < polygon.size() && polygon[at] != tris[i]) ++at;
      tri_corner.push_back(polygon_corner[at]);
    }
    tri_polygon.resize(tris.size() / 3, p);
  };
  for (std::int64_t p = 0; p < soup.num_polygons(); ++p) {
    const std::int64_t first_corner = soup.offsets[static_cast<std::size_t>(p)];
    const Index* c = soup.corners.data() + first_corner;
    const std::size_t n = static_cast<std::size_t>(soup.offsets[static_cast<std::size_t>(p) + 1] - first_corner);
    polygon.clear();
    polygon_corner.clear();
    if (n == 3) {  // repeated indices are removed with the others after this loop
      tris.insert(tris.end(), c, c + 3);
      if (tracked) {
        for (int k = 0; k < 3; ++k) tri_corner.push_back(first_corner + k);
        tri_polygon.resize(tris.size() / 3, p);
      }
      continue;
    }
    // Polygon: drop consecutive repeats (including last == first) before triangulating.
    for (std::size_t i = 0; i < n; ++i) {
      if (polygon.empty() || polygon.back() != c[i]) {
        polygon.push_back(c[i]);
        polygon_corner.push_back(first_corner + static_cast<std::int64_t>(i));
      }
    }
    while (polygon.size() > 1 && polygon.back() == polygon.front()) {
      polygon.pop_back();
      polygon_corner.pop_back();
    }
    std::vector<Index> distinct = polygon;
    std::sort(distinct.begin(), distinct.end());
    if (std::unique(distinct.begin(), distinct.end()) - distinct.begin() < 3) {
      ++report.repeated_index_faces_removed;
      continue;
    }
    const std::size_t first = tris.size();
    if (polygon.size() == 3) {
      tris.insert(tris.end(), polygon.begin(), polygon.end());
      track_new(first, p);
      continue;
    }
    ++report.polygons_triangulated;
    if (!triangulate_polygon(soup.xyz.data(), polygon.data(), polygon.size(), edges, tris)) ++report.polygons_fanned;
    track_new(first, p);
  }

  Mesh mesh;
  mesh.V = Eigen::Map<const Vertices>(soup.xyz.data(), nv, 3);
  const double diagonal = bounding_box(mesh.V).diagonal();
  // Geometry squares lengths twice (areas from squared cross products), so sizes beyond this
  // range overflow to inf or underflow to 0; real meshes are nowhere near it. A zero diagonal
  // (every vertex at one point, or coordinates so small that it underflows) has no geometry to
  // work on: it would also disable the zero-area filter below, which is relative to it.
  if (diagonal == 0)
    fail(name, "the bounding box has zero size (all vertices at one point, or coordinates too small to compute with)");
  if (!(diagonal <= kMaxDiagonal && diagonal >= kMinDiagonal))
    fail(name, fmt::format("bounding-box diagonal {:g} is outside the supported range [{:g}, {:g}]", diagonal,
                           kMinDiagonal, kMaxDiagonal));
  const double min_area = degenerate_area_bound(diagonal);

  // Faces with a repeated index (fanning a polygon with a repeated corner makes them too),
  // duplicates and zero-area faces are removed, or with keep_face_list counted and kept.
  const bool keep = options.keep_face_list;
  const std::size_t num_tris = tris.size() / 3;
  std::vector<char> repeated(num_tris, 0);
  for (std::size_t f = 0; f < num_tris; ++f) {
    const Index a = tris[3 * f], b = tris[3 * f + 1], c = tris[3 * f + 2];
    repeated[f] = a == b || b == c || c == a;
  }
  const std::vector<char> duplicate = find_duplicate_faces(tris.data(), tris.size() / 3, nv);
  std::vector<char> zero_area(num_tris, 0);
  if (options.remove_zero_area_faces || keep) {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, num_tris, 16384), [&](const auto& range) {
      for (std::size_t f = range.begin(); f != range.end(); ++f) {
        const Eigen::Vector3d a = mesh.V.row(tris[3 * f]);
        const Eigen::Vector3d b = mesh.V.row(tris[3 * f + 1]);
        const Eigen::Vector3d c = mesh.V.row(tris[3 * f + 2]);
        zero_area[f] = 0.5 * (b - a).cross(c - a).norm() < min_area;
      }
    });
  }
  std::vector<std::int64_t> kept_source;  // the triangle each kept face was, when tracking
  std::size_t kept = 0;
  for (std::size_t f = 0; f < num_tris; ++f) {
    if (keep) {
      if (repeated[f] || zero_area[f])
        ++report.degenerate_faces_kept;
      else if (duplicate[f])
        ++report.duplicate_faces_kept;
    } else if (repeated[f]) {
      ++report.repeated_index_faces_removed;
      continue;
    } else if (duplicate[f]) {
      ++report.duplicate_faces_removed;
      continue;
    } else if (zero_area[f]) {
      ++report.zero_area_faces_removed;
      continue;
    }
    for (int k = 0; k < 3; ++k)
      tris[3 * kept + static_cast<std::size_t>(k)] = tris[3 * f + static_cast<std::size_t>(k)];
    if (track) kept_source.push_back(static_cast<std::int64_t>(f));
    ++kept;
  }
  if (kept == 0) fail(name, "no valid faces remain (all faces are degenerate or repeated)");
  mesh.F = Eigen::Map<const Faces>(tris.data(), static_cast<Eigen::Index>(kept), 3);

  // Channels follow the faces kept: a face row per face from its polygon, corner rows from
  // its corners.
  MeshAttributes& attributes = mesh.attributes;
  attributes = std::move(soup.attributes);
  for (AttributeChannel& channel : attributes.face) {
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> rows(static_cast<Eigen::Index>(kept),
                                                                                channel.width());
    for (std::size_t f = 0; f < kept; ++f) {
      const std::int64_t p = source_of(static_cast<std::size_t>(kept_source[f]));
      if (p < channel.rows())
        rows.row(static_cast<Eigen::Index>(f)) = channel.values.row(static_cast<Eigen::Index>(p));
      else
        rows.row(static_cast<Eigen::Index>(f)).setZero();  // a strip's triangle: the element had no row
    }
    channel.values = std::move(rows);
  }
  for (std::size_t c = 0; c < attributes.corner.size(); ++c) {
    CornerChannel& channel = attributes.corner[c];
    channel.corners.resize(static_cast<Eigen::Index>(kept), 3);
    for (std::size_t f = 0; f < kept; ++f)
      for (int k = 0; k < 3; ++k)
        channel.corners(static_cast<Eigen::Index>(f), k) =
            soup.corner_rows[c][static_cast<std::size_t>(corner_of(static_cast<std::size_t>(kept_source[f]), k))];
  }
  if (!soup.rgb.empty()) {
    AttributeChannel& color = attributes.vertex.emplace_back();
    color.name = "color";
    color.components = {"red", "green", "blue"};
    color.type = ScalarType::UInt8;
    color.role = AttributeRole::Color;
    color.values =
        Eigen::Map<const Eigen::Matrix<std::uint8_t, Eigen::Dynamic, 3, Eigen::RowMajor>>(soup.rgb.data(), nv, 3)
            .cast<double>();
  }
  mesh.comments = std::move(soup.comments);
  for (const auto& [what, count] : soup.not_kept) report.not_kept.push_back(fmt::format("{} ({})", what, count));

  // Remove unreferenced vertices, keeping the order of the others.
  std::vector<Index> new_index(static_cast<std::size_t>(nv), -1);
  for (Eigen::Index i = 0; i < mesh.F.size(); ++i) new_index[static_cast<std::size_t>(mesh.F.data()[i])] = 0;
  Index used = 0;
  for (auto& v : new_index) {
    if (v == 0) v = used++;
  }
  if (used < nv && keep) {
    report.unreferenced_vertices_kept += nv - used;
  } else if (used < nv) {
    report.unreferenced_vertices_removed += nv - used;
    auto compact_rows = [&](auto& matrix) {
      for (Index v = 0; v < nv; ++v) {
        if (new_index[static_cast<std::size_t>(v)] >= 0)
          matrix.row(new_index[static_cast<std::size_t>(v)]) = matrix.row(v);
      }
      matrix.conservativeResize(used, Eigen::NoChange);
    };
    compact_rows(mesh.V);
    for (AttributeChannel& channel : attributes.vertex) compact_rows(channel.values);
    for (Eigen::Index i = 0; i < mesh.F.size(); ++i)
      mesh.F.data()[i] = new_index[static_cast<std::size_t>(mesh.F.data()[i])];
  }
  return mesh;
}

}  // namespace io_detail

std::string lowercase_extension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext;
}

bool is_gzip_path(const std::filesystem::path& path) {
  return lowercase_extension(path) == ".gz";
}

bool is_mesh_path(const std::filesystem::path& path) {
  if (is_gzip_path(path)) {
    const std::string ext = lowercase_extension(path.stem());
    return ext == ".obj" || ext == ".ply" || ext == ".off" || ext == ".stl";
  }
  const std::string ext = lowercase_extension(path);
  return ext == ".obj" || ext == ".ply" || ext == ".off" || ext == ".stl" || ext == ".gltf" || ext == ".glb";
}

MeshFormat format_from_path(const std::filesystem::path& path) {
  const std::string ext = lowercase_extension(is_gzip_path(path) ? path.stem() : path);
  if (ext == ".obj") return MeshFormat::Obj;
  if (ext == ".ply") return MeshFormat::Ply;
  if (ext == ".off") return MeshFormat::Off;
  if (ext == ".stl") return MeshFormat::Stl;
  if (ext == ".gltf" || ext == ".glb") {
    if (is_gzip_path(path)) io_detail::fail(path.string(), "gzip-compressed glTF is not supported (.glb is compact)");
    return MeshFormat::Gltf;
  }
  io_detail::fail(
      path.string(),
      ext.empty() ? "no file extension; expected .obj, .ply, .off, .stl (optionally .gz), .gltf or .glb"
                  : "unknown extension '" + ext + "'; expected .obj, .ply, .off, .stl (optionally .gz), .gltf or .glb");
}

const char* format_name(MeshFormat format) {
  switch (format) {
    case MeshFormat::Obj:
      return "OBJ";
    case MeshFormat::Ply:
      return "PLY";
    case MeshFormat::Off:
      return "OFF";
    case MeshFormat::Stl:
      return "STL";
    case MeshFormat::Gltf:
      return "glTF";
  }
  return "?";
}

std::vector<std::string> ReadReport::warnings() const {
  std::vector<std::string> out;
  auto add = [&](std::int64_t count, const char* what) {
    if (count > 0) out.push_back(fmt::format("{} {}", count, what));
  };
  if (format_differs_from_extension)
    out.push_back(fmt::format("the file's content is {}, not what its extension says; read as {}", format_name(format),
                              format_name(format)));
  add(ply_extra_values_lines, "lines had more values than their element declares; the extra values were ignored");
  add(polygons_triangulated, "polygons triangulated");
  add(polygons_fanned, "polygons had no planar triangulation (self-intersecting or folded) and were fanned");
  add(vertices_welded, "duplicate vertices welded");
  add(unreferenced_vertices_removed, "unreferenced vertices removed");
  add(repeated_index_faces_removed, "faces with a repeated vertex removed");
  add(duplicate_faces_removed, "duplicate faces removed");
  add(zero_area_faces_removed, "zero-area faces removed");
  add(strip_triangles, "triangles read from triangle strips");
  add(degenerate_faces_kept, "zero-area faces or faces with a repeated vertex kept (their vertices are held)");
  add(duplicate_faces_kept, "duplicate faces kept (their vertices are held)");
  add(unreferenced_vertices_kept, "unreferenced vertices kept (held)");
  if (!not_kept.empty()) {
    std::string list;
    for (const std::string& item : not_kept) list += (list.empty() ? "" : ", ") + item;
    out.push_back("not kept: " + list);
  }
  return out;
}

namespace {

// The format the first bytes show, when they show one beyond doubt: "ply" on the first line, an
// OFF keyword as the first token, or "solid" followed by "facet"/"endsolid" (ASCII STL). OBJ
// has no signature. Binary STL is recognised by its size (84 + 50 x its triangle count).
// `whole` is the complete content when it is all in memory (plain files), else empty.
std::optional<MeshFormat> format_from_content(std::string_view head, std::string_view whole) {
  if (head.substr(0, 4) == "ply\n" || head.substr(0, 5) == "ply\r\n") return MeshFormat::Ply;
  const std::string no_name;
  io_detail::TextScanner in(head, no_name);
  const std::string_view first = in.token(/*comments=*/true);
  static constexpr std::string_view off_keywords[] = {"OFF",   "COFF",   "NOFF",   "CNOFF",
                                                      "STOFF", "STCOFF", "STNOFF", "STCNOFF"};
  if (std::find(std::begin(off_keywords), std::end(off_keywords), first) != std::end(off_keywords))
    return MeshFormat::Off;
  if (first == "solid" && head.find('\0') == std::string_view::npos) {
    in.skip_line();
    const std::string_view second = in.token();
    if (second == "facet" || second == "endsolid") return MeshFormat::Stl;
  }
  if (!whole.empty() && io_detail::has_binary_stl_size(whole)) return MeshFormat::Stl;
  return std::nullopt;
}

// Whether `head` has a NUL byte outside OBJ '#' comments: binary data, not an OBJ file. A comment
// may hold anything up to its line's end (or, ending in a backslash, the next line's, as
// parse_obj reads it), so a NUL written there by some tool does not reject the file.
bool nul_outside_obj_comments(std::string_view head) {
  for (std::size_t p = 0; p < head.size(); ++p) {
    if (head[p] == '\0') return true;
    if (head[p] != '#') continue;
    for (std::size_t line = p;;) {  // skip the comment, continued lines included
      const std::size_t nl = head.find('\n', line);
      if (nl == std::string_view::npos) return false;
      std::size_t end = nl;
      while (end > line && (head[end - 1] == ' ' || head[end - 1] == '\t' || head[end - 1] == '\r')) --end;
      p = nl;
      if (end == line || head[end - 1] != '\\') break;
      line = nl + 1;
    }
  }
  return false;
}

Mesh read_mesh_checked(std::string_view bytes, MeshFormat format, const std::string& name, ReadReport& r,
                       const ReadOptions& options) {
  r = ReadReport{};
  r.format = format;
  io_detail::PolygonSoup soup;
  {
    io_detail::ByteSource source(bytes, name, {options.max_inflate_ratio, options.inflate_floor_bytes});
    r.gzip = source.is_gzip();
    // The first bytes decide what the file is, before any bulk is read or inflated.
    constexpr std::size_t kHeadBytes = 4096;
    source.request(kHeadBytes, 0);
    const std::string_view head = source.data().substr(0, kHeadBytes);
    if (head.empty()) io_detail::fail(name, "the file is empty");
    const std::optional<MeshFormat> content =
        format_from_content(head, source.complete() ? source.data() : std::string_view());
    if (content && *content != format) {
      r.format = *content;
      r.format_differs_from_extension = true;
    } else if (!content && format == MeshFormat::Obj && nul_outside_obj_comments(head)) {
      io_detail::fail(name, "not an OBJ file (it holds binary data, and OBJ is text)");
    }
    switch (r.format) {
      case MeshFormat::Obj:
        soup = io_detail::parse_obj(source, name);
        break;
      case MeshFormat::Ply:
        soup = io_detail::parse_ply(source, name, r);
        break;
      case MeshFormat::Off:
        soup = io_detail::parse_off(source, name, r);
        break;
      case MeshFormat::Stl:
        soup = io_detail::parse_stl(source, name, r);
        break;
      case MeshFormat::Gltf:
        break;  // read_mesh_from_memory hands glTF over before this
    }
    source.verify_rest();
  }  // the text is freed before the mesh is built
  return io_detail::soup_to_mesh(std::move(soup), name, r, options);
}

}  // namespace

double default_max_inflate_ratio() {
  // Read once: the environment does not change under a running program in any way we support.
  static const double ratio = [] {
    const char* text = std::getenv("VERTEXFLOW_MAX_INFLATE_RATIO");
    if (text == nullptr) return 32.0;
    char* end = nullptr;
    const double value = std::strtod(text, &end);
    return end != text && *end == '\0' && value > 0 ? value : 32.0;
  }();
  return ratio;
}

Mesh read_mesh_from_memory(std::string_view bytes, MeshFormat format, const std::string& name, ReadReport* report,
                           const ReadOptions& options) {
  ReadReport local;
  try {
    if (format == MeshFormat::Gltf) {
      ReadReport& r = report ? *report : local;
      r = ReadReport{};
      r.format = MeshFormat::Gltf;
      return io_detail::read_gltf_bytes(bytes, name, r, options);
    }
    return read_mesh_checked(bytes, format, name, report ? *report : local, options);
  } catch (const std::bad_alloc&) {
    io_detail::fail(name, "out of memory while reading the mesh");
  } catch (const std::length_error&) {
    io_detail::fail(name, "out of memory while reading the mesh (a size beyond what a vector can hold)");
  }
}

Mesh read_mesh(const std::filesystem::path& path, ReadReport* report, const ReadOptions& options) {
  const MeshFormat format = format_from_path(path);
  if (format == MeshFormat::Gltf) {  // external buffers and images are found beside the file
    ReadReport local;
    ReadReport& r = report ? *report : local;
    r = ReadReport{};
    r.format = MeshFormat::Gltf;
    try {
      return io_detail::read_gltf_file(path, r, options);
    } catch (const std::bad_alloc&) {
      io_detail::fail(path.string(), "out of memory while reading the mesh");
    }
  }
  io_detail::FileBytes bytes;
  try {
    bytes = io_detail::read_file_bytes(path);
  } catch (const std::bad_alloc&) {
    io_detail::fail(path.string(), "out of memory while loading the file");
  }
  return read_mesh_from_memory(bytes.view(), format, path.string(), report, options);
}

}  // namespace vertexflow
