// STL reader (ASCII and binary). STL stores each facet's three corners separately; they are
// welded into shared vertices afterwards (soup_to_mesh).
//
// Written here: the format is fixed-size records (binary) or a handful of keywords (ASCII),
// and the ASCII/binary decision must not trust the "solid" prefix, which many binary writers
// also emit.
#include "io_internal.h"

#include <fmt/format.h>

namespace vertexflow::io_detail {
namespace {

constexpr std::size_t kBinaryHeader = 84;  // 80-byte comment + uint32 triangle count
constexpr std::size_t kBinaryRecord = 50;  // normal, 3 corners (float32 x 12), uint16 attribute

// ASCII STL starts with "solid", but so do many binary files' 80-byte comments. A binary file
// matches its declared size exactly, and its records hold NUL bytes (zero coordinates, the
// attribute count), which text never does: both say binary, so that a binary file with a
// "solid" comment and a stray trailing byte is read as binary, not as empty text.
bool looks_ascii(std::string_view bytes) {
  std::size_t i = 0;
  while (i < bytes.size() && TextScanner::is_space(bytes[i])) ++i;
  if (bytes.substr(i, 5) != "solid") return false;
  if (has_binary_stl_size(bytes)) return false;
  return bytes.substr(0, 4096).find('\0') == std::string_view::npos;
}

}  // namespace

bool has_binary_stl_size(std::string_view bytes) {
  if (bytes.size() < kBinaryHeader) return false;
  const std::uint64_t count = load_scalar<std::uint32_t>(bytes.data() + 80, !host_is_little_endian());
  return kBinaryHeader + count * kBinaryRecord == bytes.size();
}

namespace {

PolygonSoup parse_ascii(std::string_view bytes, const std::string& name) {
  PolygonSoup soup;
  TextScanner in(bytes, name);
  int corners_in_facet = 0;
  bool in_facet = false;
  for (;;) {
    const std::string_view tok = in.token();
    if (tok.empty()) break;
    if (tok == "vertex") {
      if (!in_facet) in.error("'vertex' outside a facet");
      const double x = in.next_double("a vertex coordinate");
      const double y = in.next_double("a vertex coordinate");
      const double z = in.next_double("a vertex coordinate");
      soup.add_vertex(x, y, z);
      soup.corners.push_back(static_cast<Index>(soup.num_vertices() - 1));
      ++corners_in_facet;
    } else if (tok == "facet") {
      if (in_facet) in.error("'facet' inside a facet (missing 'endfacet')");
      in_facet = true;
      corners_in_facet = 0;
      in.skip_line();  // "normal nx ny nz": recomputed from the corners when needed
    } else if (tok == "endfacet") {
      if (!in_facet) in.error("'endfacet' without 'facet'");
      if (corners_in_facet != 3) in.error(fmt::format("a facet has {} vertices; STL facets have 3", corners_in_facet));
      soup.end_polygon();
      in_facet = false;
    } else if (tok == "solid" || tok == "endsolid") {
      in.skip_line();  // optional name
    } else if (tok == "outer" || tok == "loop" || tok == "endloop") {
    } else {
      in.error("unexpected '" + TextScanner::printable(tok) + "' in ASCII STL");
    }
  }
  if (in_facet) in.error("file ends inside a facet (truncated?)");
  return soup;
}

PolygonSoup parse_binary(std::string_view bytes, const std::string& name) {
  if (bytes.size() < kBinaryHeader)
    fail(name, fmt::format("binary STL needs at least {} bytes, the file has {} (and is not ASCII STL)",
                           kBinaryHeader, bytes.size()));
  const bool swap = !host_is_little_endian();  // binary STL is little-endian
  const std::uint64_t count = load_scalar<std::uint32_t>(bytes.data() + 80, swap);
  const std::uint64_t needed = kBinaryHeader + count * kBinaryRecord;
  if (needed > bytes.size())
    fail(name, fmt::format("binary STL header declares {} triangles ({} bytes), but the file has {} bytes (truncated?)",
                           count, needed, bytes.size()));
  if (3 * count > static_cast<std::uint64_t>(std::numeric_limits<Index>::max()))
    fail(name, fmt::format("{} triangles exceed the supported maximum", count));
  PolygonSoup soup;
  soup.weld_vertices = true;
  soup.xyz.resize(9 * count);
  soup.corners.resize(3 * count);
  soup.offsets.resize(count + 1);
  for (std::size_t t = 0; t < count; ++t) {
    const char* record = bytes.data() + kBinaryHeader + t * kBinaryRecord + 12;  // skip the normal
    for (std::size_t c = 0; c < 9; ++c) soup.xyz[9 * t + c] = load_scalar<float>(record + 4 * c, swap);
    for (std::size_t c = 0; c < 3; ++c) soup.corners[3 * t + c] = static_cast<Index>(3 * t + c);
    soup.offsets[t + 1] = static_cast<std::int64_t>(3 * (t + 1));
  }
  return soup;
}

}  // namespace

PolygonSoup parse_stl(ByteSource& source, const std::string& name, ReadReport& report) {
  // ASCII or binary is decided with the total size (a binary file matches its declared size).
  source.request_all();
  const std::string_view bytes = source.data();
  if (looks_ascii(bytes)) {
    PolygonSoup soup = parse_ascii(bytes, name);
    soup.weld_vertices = true;
    return soup;
  }
  report.binary = true;
  return parse_binary(bytes, name);
}

}  // namespace vertexflow::io_detail
