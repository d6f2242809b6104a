// OFF reader: ASCII and binary ("OFF BINARY", big-endian), with the optional [ST][C][N]
// prefixes (texture coordinates, colours, normals per vertex), which are read past.
//
// Written here: Debian has no small OFF library, the format is a few lines, and the reader
// must bound allocations by the file's size (a header's counts are checked before reserving).
#include "io_internal.h"

#include <fmt/format.h>

#include <optional>

namespace vertexflow::io_detail {
namespace {

struct OffHeader {
  bool texcoords = false, colors = false, normals = false, binary = false;
};

// Parses the keyword, e.g. "STCNOFF"; 4D ("4OFF") and n-dimensional ("nOFF") are refused.
OffHeader parse_keyword(std::string_view keyword, const std::string& name) {
  OffHeader h;
  if (keyword.size() < 3 || keyword.substr(keyword.size() - 3) != "OFF")
    fail(name, "not an OFF file (expected 'OFF' at the start, found '" + TextScanner::printable(keyword) + "')");
  std::string_view prefix = keyword.substr(0, keyword.size() - 3);
  if (prefix.substr(0, 2) == "ST") h.texcoords = true, prefix.remove_prefix(2);
  if (!prefix.empty() && prefix.front() == 'C') h.colors = true, prefix.remove_prefix(1);
  if (!prefix.empty() && prefix.front() == 'N') h.normals = true, prefix.remove_prefix(1);
  if (!prefix.empty())
    fail(name, "unsupported OFF variant '" + TextScanner::printable(keyword) + "' (only 3D [ST][C][N]OFF)");
  return h;
}

void check_counts(std::int64_t nv, std::int64_t nf, std::uint64_t available, std::size_t vertex_bytes,
                  std::size_t face_bytes, const std::string& name) {
  if (nv < 0 || nf < 0) fail(name, fmt::format("negative element count in header ({} vertices, {} faces)", nv, nf));
  const auto fits = static_cast<std::uint64_t>(nv) * vertex_bytes + static_cast<std::uint64_t>(nf) * face_bytes;
  if (static_cast<std::uint64_t>(nv) > available || static_cast<std::uint64_t>(nf) > available || fits > available + 1)
    fail(name, fmt::format("header declares {} vertices and {} faces, but the remaining {} bytes cannot hold them", nv,
                           nf, available));
}

// One binary layout: byte order, and whether each face ends with a colour count. The
// Geomview definition is big-endian with a colour count; common writers (PMP, and so the
// meshes in pmp-data such as amo.off) write the host's little-endian order and no colour count.
struct BinaryLayout {
  bool big_endian = true;
  bool face_colors = true;
};

// Parses with one layout; sets `consumed` to the bytes read. Throws IoError on any mismatch.
PolygonSoup parse_binary(std::string_view bytes, std::size_t start, const OffHeader& h, BinaryLayout layout,
                         const std::string& name, std::size_t& consumed) {
  const bool swap = layout.big_endian == host_is_little_endian();
  std::size_t pos = start;
  auto need = [&](std::size_t n, const char* what) {
    if (n > bytes.size() - pos)
      fail(name, fmt::format("unexpected end of file while reading {} (file truncated?)", what));
  };
  need(12, "the element counts");
  const std::int64_t nv = load_scalar<std::int32_t>(bytes.data() + pos, swap);
  const std::int64_t nf = load_scalar<std::int32_t>(bytes.data() + pos + 4, swap);
  pos += 12;  // the edge count is unused
  const std::size_t floats_per_vertex = 3 + (h.normals ? 3 : 0) + (h.colors ? 4 : 0) + (h.texcoords ? 2 : 0);
  check_counts(nv, nf, bytes.size() - pos, 4 * floats_per_vertex, 16, name);
  PolygonSoup soup;
  soup.xyz.resize(3 * static_cast<std::size_t>(nv));
  need(4 * floats_per_vertex * static_cast<std::size_t>(nv), "the vertices");
  for (std::size_t v = 0; v < static_cast<std::size_t>(nv); ++v) {
    for (std::size_t c = 0; c < 3; ++c) soup.xyz[3 * v + c] = load_scalar<float>(bytes.data() + pos + 4 * c, swap);
    pos += 4 * floats_per_vertex;
  }
  soup.offsets.reserve(static_cast<std::size_t>(nf) + 1);
  soup.corners.reserve(3 * static_cast<std::size_t>(nf));
  for (std::int64_t f = 0; f < nf; ++f) {
    need(4, "a face");
    const std::int64_t n = load_scalar<std::int32_t>(bytes.data() + pos, swap);
    pos += 4;
    if (n < 0 || static_cast<std::uint64_t>(n) > (bytes.size() - pos) / 4)
      fail(name, fmt::format("face {} declares {} vertices, more than the file holds", f, n));
    for (std::int64_t k = 0; k < n; ++k) {
      soup.corners.push_back(load_scalar<std::int32_t>(bytes.data() + pos, swap));
      pos += 4;
    }
    soup.end_polygon();
    if (layout.face_colors) {
      need(4, "a face's colour count");
      const std::int64_t colors = load_scalar<std::int32_t>(bytes.data() + pos, swap);
      pos += 4;
      if (colors < 0 || colors > 4) fail(name, fmt::format("face {} has an invalid colour count {}", f, colors));
      need(4 * static_cast<std::size_t>(colors), "a face's colour");
      pos += 4 * static_cast<std::size_t>(colors);
    }
  }
  consumed = pos;
  return soup;
}

// Tries the layouts in order of the standard's preference and takes the first that reads the
// whole file exactly; failing that, the first that reads without error; failing that, the
// standard layout's error is reported.
PolygonSoup parse_binary(std::string_view bytes, std::size_t start, const OffHeader& h, const std::string& name) {
  const BinaryLayout layouts[] = {{true, true}, {true, false}, {false, true}, {false, false}};
  std::optional<PolygonSoup> partial;
  std::optional<IoError> first_error;
  for (const BinaryLayout& layout : layouts) {
    try {
      std::size_t consumed = 0;
      PolygonSoup soup = parse_binary(bytes, start, h, layout, name, consumed);
      if (consumed == bytes.size()) return soup;
      if (!partial) partial = std::move(soup);
    } catch (const IoError& e) {
      if (!first_error) first_error = e;
    }
  }
  if (partial) return std::move(*partial);
  throw *first_error;
}

}  // namespace

PolygonSoup parse_off(ByteSource& source, const std::string& name, ReadReport& report) {
  TextScanner in(source, name);
  std::vector<std::string> comments;
  in.collect_comments(&comments);
  const OffHeader keyword = parse_keyword(in.token(/*comments=*/true), name);
  OffHeader h = keyword;
  // "OFF BINARY" on the first line switches to the binary layout after that line.
  in.skip_blanks();
  if (in.lookahead(6) == "BINARY") {
    in.advance(6);
    in.skip_line();
    h.binary = true;
    report.binary = true;
    // The layout is chosen by which one reads the whole file exactly, so it needs the size.
    source.request_all();
    PolygonSoup soup = parse_binary(source.data(), in.position() - source.offset(), h, name);
    soup.comments = std::move(comments);
    return soup;
  }
  const std::int64_t nv = in.next_int("the vertex count", true);
  const std::int64_t nf = in.next_int("the face count", true);
  if (!in.at_line_end()) in.token_on_line();  // the edge count, unused
  in.skip_line();
  // Shortest records: "0 0 0\n" for a vertex, "3 0 1 2\n" for a face.
  check_counts(nv, nf, in.remaining_bound(), 6, 8, name);
  PolygonSoup soup;
  soup.comments = std::move(comments);
  in.collect_comments(&soup.comments);
  soup.xyz.reserve(3 * static_cast<std::size_t>(nv));  // resident only as vertices fill it (read_ply.cpp)
  for (std::int64_t v = 0; v < nv; ++v) {
    const double x = in.next_double("a vertex coordinate", true);
    const double y = in.next_double("a vertex coordinate", true);
    const double z = in.next_double("a vertex coordinate", true);
    soup.add_vertex(x, y, z);
    in.skip_line();  // normals, colours, texture coordinates
  }
  soup.offsets.reserve(static_cast<std::size_t>(nf) + 1);
  for (std::int64_t f = 0; f < nf; ++f) {
    const std::int64_t n = in.next_int("a face's vertex count", true);
    if (n < 0 || static_cast<std::uint64_t>(n) > in.remaining_bound() / 2 + 1)
      in.error(fmt::format("face {} declares {} vertices, more than the file holds", f, n));
    for (std::int64_t k = 0; k < n; ++k) {
      const std::int64_t index = in.next_int("a face vertex index");
      if (index < 0 || index > std::numeric_limits<Index>::max())
        in.error(fmt::format("face {} has invalid vertex index {}", f, index));
      soup.corners.push_back(static_cast<Index>(index));
    }
    soup.end_polygon();
    in.skip_line();  // an optional face colour
  }
  return soup;
}

}  // namespace vertexflow::io_detail
