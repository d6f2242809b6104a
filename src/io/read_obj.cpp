// Wavefront OBJ reader: `v` positions and `f` faces (v, v/t, v//n, v/t/n, negative indices),
// and '#' comments (io.h); every other statement (vt, vn, g, o, s, usemtl, mtllib, l, p, ...)
// is skipped, and those that carry attributes are counted in ReadReport::not_kept (until they
// are kept: docs/attributes.md).
//
// A line whose last character other than blanks is a backslash continues on the next line, as
// the OBJ specification allows (a long `f` statement split over lines). This holds for every
// line, comments included, as in Blender's importer and C. The backslash and line break read as
// a blank, so "1\" followed by "2" gives two indices, not "12". Lines are joined as the tokens
// are read rather than copied into a buffer, so a statement's length is bounded only by the
// input (its size, or the gzip inflation limit), and error messages give the statement's first
// line.
//
// Written here rather than taken from tinyobjloader (Debian's libtinyobjloader-dev): that
// library builds per-shape attribute arrays and materials we do not need, keeps texture and
// normal indices per corner (three times the index memory), and reports no line numbers.
// Numbers are parsed with std::from_chars (exact, locale-free).
#include "io_internal.h"

#include <fmt/format.h>

namespace vertexflow::io_detail {
namespace {

// Reads the tokens of one statement at a time, across line continuations.
class ObjStatements {
 public:
  explicit ObjStatements(TextScanner& in) : in_(in) {}

  // Skips blanks and line continuations. Returns false at a backslash that continues nothing
  // (more text follows it on its line), having moved past it.
  bool skip_blanks() {
    for (;;) {
      in_.skip_blanks();
      if (in_.peek() != '\\') return true;
      in_.advance(1);
      in_.skip_blanks();
      if (in_.at_end()) return true;
      if (in_.peek() != '\n') return false;
      in_.advance(1);
      crossed_line_break();
    }
  }

  // The next token of the statement, or empty at its end.
  std::string_view token() {
    const std::string_view tok = in_.token_on_line();
    if (tok.empty() || tok.back() != '\\') [[likely]]
      return tok;
    return token_ending_in_backslash(tok);
  }

  // Moves past the statement's last line; the next statement starts there.
  void end() {
    if (in_.skip_line_continued()) [[unlikely]]
      end_continued();
    if (continued_ > 0) [[unlikely]] {
      continued_ = 0;
      in_.report_lines_back(0);
    }
  }

 private:
  // A backslash ending a line continues it and is no part of a token. The token is copied
  // because looking past it may move the scanner's window.
  [[gnu::noinline, gnu::cold]] std::string_view token_ending_in_backslash(std::string_view tok) {
    for (;;) {
      held_.assign(tok.data(), tok.size() - 1);
      in_.skip_blanks();
      if (in_.at_end()) return held_;
      if (in_.peek() != '\n') {
        held_.push_back('\\');  // not at the line's end: the backslash is part of the token
        return held_;
      }
      in_.advance(1);
      crossed_line_break();
      if (!held_.empty()) return held_;
      tok = in_.token_on_line();  // the line held a lone backslash: the statement goes on
      if (tok.empty() || tok.back() != '\\') return tok;
    }
  }

  [[gnu::noinline, gnu::cold]] void end_continued() {
    do {
      crossed_line_break();
    } while (in_.skip_line_continued());
  }

  // Errors keep naming the statement's first line.
  void crossed_line_break() { in_.report_lines_back(++continued_); }

  TextScanner& in_;
  std::uint64_t continued_ = 0;  // line breaks crossed in the current statement
  std::string held_;
};

// The attribute statements a mesh does not keep yet, by keyword (ReadReport::not_kept).
void count_skipped_statement(std::string_view head, PolygonSoup& soup) {
  const std::string_view keyword = head.substr(0, head.find_first_of(" \t\r\n\\"));
  static constexpr std::pair<std::string_view, std::string_view> kinds[] = {{"vt", "texture coordinates vt"},
                                                                            {"vn", "normals vn"},
                                                                            {"usemtl", "material switches usemtl"},
                                                                            {"mtllib", "material libraries mtllib"},
                                                                            {"g", "groups g"},
                                                                            {"o", "objects o"},
                                                                            {"s", "smoothing groups s"},
                                                                            {"vp", "parameter vertices vp"},
                                                                            {"l", "lines l"}};
  if (keyword == "s") {  // "s off" and "s 0" are no smoothing group
    std::string_view rest = head.substr(1);
    rest.remove_prefix(std::min(rest.find_first_not_of(" \t"), rest.size()));
    if (rest.substr(0, 3) == "off" || rest.substr(0, 1) == "0") return;
  }
  for (const auto& [word, what] : kinds)
    if (keyword == word) return soup.count_not_kept(what);
}

}  // namespace

PolygonSoup parse_obj(ByteSource& source, const std::string& name) {
  PolygonSoup soup;
  soup.index_base = 1;
  TextScanner in(source, name);
  ObjStatements statement(in);
  // Positive indices may refer to vertices defined later in the file, so they are resolved
  // and range-checked once the whole file is read (soup_to_mesh).
  while (!in.at_end()) {
    if (!statement.skip_blanks()) {  // a line starting with a stray backslash
      statement.end();
      continue;
    }
    const std::string_view rest = in.lookahead(2);
    const char keyword = rest.size() >= 2 ? rest[0] : '\0';
    const char after = rest.size() >= 2 ? rest[1] : '\0';
    // "v\" ending a line is a `v` statement continued on the next line.
    if ((keyword == 'v' || keyword == 'f') && (after == ' ' || after == '\t' || after == '\\')) {
      in.advance(1);
      if (after == '\\' && !statement.skip_blanks()) {  // "v\x": no statement we read
        statement.end();
        continue;
      }
    } else {
      // A comment's first line (a continued one's further lines are skipped with it).
      if (in.peek() == '#') [[unlikely]]
        in.peek_comment(soup.comments);
      else
        count_skipped_statement(in.lookahead(12), soup);
      statement.end();
      continue;
    }
    if (keyword == 'v') {
      double xyz[3];
      for (double& x : xyz) {
        const std::string_view tok = statement.token();
        if (tok.empty()) in.error("a vertex needs three coordinates");
        x = in.to_double(tok, "a vertex coordinate");
      }
      soup.add_vertex(xyz[0], xyz[1], xyz[2]);
    } else {
      const std::int64_t defined = soup.num_vertices();
      for (;;) {
        const std::string_view tok = statement.token();
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
    }
    statement.end();
  }
  return soup;
}

}  // namespace vertexflow::io_detail
