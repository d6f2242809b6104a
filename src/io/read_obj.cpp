// Wavefront OBJ reader: `v` positions and `f` faces (v, v/t, v//n, v/t/n, negative indices);
// every other statement (vt, vn, g, o, s, usemtl, mtllib, l, p, ...) is skipped.
//
// Written here rather than taken from tinyobjloader (Debian's libtinyobjloader-dev): that
// library builds per-shape attribute arrays and materials we do not need, keeps texture and
// normal indices per corner (three times the index memory), and reports no line numbers.
// Numbers are parsed with std::from_chars (exact, locale-free).
#include "io_internal.h"

#include <fmt/format.h>

namespace vertexflow::io_detail {

PolygonSoup parse_obj(ByteSource& source, const std::string& name) {
  PolygonSoup soup;
  soup.index_base = 1;
  TextScanner in(source, name);
  // Positive indices may refer to vertices defined later in the file, so they are resolved
  // and range-checked once the whole file is read (soup_to_mesh).
  while (!in.at_end()) {
    in.skip_blanks();
    const std::string_view rest = in.lookahead(2);
    if (rest.size() >= 2 && rest[0] == 'v' && (rest[1] == ' ' || rest[1] == '\t')) {
      in.advance(1);
      double xyz[3];
      for (double& x : xyz) {
        const std::string_view tok = in.token_on_line();
        if (tok.empty()) in.error("a vertex needs three coordinates");
        x = in.to_double(tok, "a vertex coordinate");
      }
      soup.add_vertex(xyz[0], xyz[1], xyz[2]);
      in.skip_line();
    } else if (rest.size() >= 2 && rest[0] == 'f' && (rest[1] == ' ' || rest[1] == '\t')) {
      in.advance(1);
      const std::int64_t defined = soup.num_vertices();
      for (;;) {
        const std::string_view tok = in.token_on_line();
        if (tok.empty()) break;
        std::int64_t index = 0;
        const auto [ptr, ec] = std::from_chars(tok.data(), tok.data() + tok.size(), index);
        if (ec != std::errc() || (ptr != tok.data() + tok.size() && *ptr != '/'))
          in.error("expected a face vertex index, found '" + TextScanner::printable(tok) + "'");
        if (index == 0) in.error("vertex index 0 is invalid (OBJ indices start at 1)");
        // Negative indices count back from the last vertex defined so far.
        const std::int64_t resolved = index > 0 ? index - 1 : defined + index;
        if (resolved < 0 || resolved > std::numeric_limits<Index>::max())
          in.error(fmt::format("vertex index {} is out of range ({} vertices defined so far)", index, defined));
        soup.corners.push_back(static_cast<Index>(resolved));
      }
      soup.end_polygon();
      in.skip_line();
    } else {
      in.skip_line();
    }
  }
  return soup;
}

}  // namespace vertexflow::io_detail
