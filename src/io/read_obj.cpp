// Wavefront OBJ reader: `v` positions, `f` faces (v, v/t, v//n, v/t/n, negative indices) and
// '#' comments (io.h), and what faces carry (attributes.h): `vt` and `vn` as corner channels
// "uv" and "normal" with the faces' own indices, `usemtl`, `g`, `o` and `s` as face channels
// "material", "group", "object" and "smoothing", and `mtllib` names. Other statements (vp, l,
// p, curves) are skipped and counted in ReadReport::not_kept.
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

#include <algorithm>

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

// The statements a mesh does not keep, by keyword (ReadReport::not_kept).
void count_skipped_statement(std::string_view head, PolygonSoup& soup) {
  const std::string_view keyword = head.substr(0, head.find_first_of(" \t\r\n\\"));
  static constexpr std::pair<std::string_view, std::string_view> kinds[] = {{"vp", "OBJ parameter vertices vp"},
                                                                            {"l", "OBJ lines l"},
                                                                            {"p", "OBJ points p"},
                                                                            {"curv", "OBJ curves curv"},
                                                                            {"surf", "OBJ surfaces surf"}};
  for (const auto& [word, what] : kinds)
    if (keyword == word) return soup.count_not_kept(what);
}

// What OBJ faces carry, gathered while parsing and turned into channels at the end.
struct ObjAttributes {
  std::vector<double> uv, normal;  // vt (up to 3 values, padded) and vn (3) rows
  int uv_width = 0;                // the most values a vt statement had
  // Per corner (parallel to soup.corners) the vt and vn row, once any face had one.
  std::vector<std::int32_t> uv_rows, normal_rows;
  bool uv_used = false, normal_used = false;
  // Per polygon labels, once their statement appeared: indices into the name tables, and the
  // smoothing group number.
  std::vector<double> object, group, material, smoothing;
  bool has_object = false, has_group = false, has_material = false, has_smoothing = false;
  int current_object = -1, current_group = -1, current_material = -1, current_smoothing = 0;
};

// The rest of the statement's line as one name ("g a b" is one group "a b"), blanks trimmed.
std::string rest_of_statement(ObjStatements& statement) {
  std::string name;
  for (std::string_view tok = statement.token(); !tok.empty(); tok = statement.token()) {
    if (!name.empty()) name += ' ';
    name += tok;
  }
  return name;
}

int name_index(std::vector<std::string>& names, const std::string& name) {
  for (std::size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return static_cast<int>(i);
  names.push_back(name);
  return static_cast<int>(names.size()) - 1;
}

// Resolves a vt/vn index (1-based, or negative counting back from the last defined) to a row.
std::int32_t attribute_row(std::string_view digits, std::size_t defined, const char* what, TextScanner& in) {
  std::int64_t index = 0;
  const auto [ptr, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), index);
  if (ec != std::errc() || ptr != digits.data() + digits.size())
    in.error(fmt::format("expected a {} index, found '{}'", what, TextScanner::printable(digits)));
  if (index == 0) in.error(fmt::format("{} index 0 is invalid (OBJ indices start at 1)", what));
  const std::int64_t resolved = index > 0 ? index - 1 : static_cast<std::int64_t>(defined) + index;
  if (resolved < 0 || resolved > std::numeric_limits<std::int32_t>::max())
    in.error(fmt::format("{} index {} is out of range ({} defined so far)", what, index, defined));
  return static_cast<std::int32_t>(resolved);
}

// The "t", "t/n" or "/n" after a face corner's vertex index.
void corner_attributes(std::string_view rest, PolygonSoup& soup, ObjAttributes& obj, TextScanner& in) {
  const std::size_t slash = rest.find('/');
  const std::string_view t = rest.substr(0, slash);
  const std::string_view n = slash == std::string_view::npos ? std::string_view() : rest.substr(slash + 1);
  const std::size_t corner = soup.corners.size() - 1;
  if (!t.empty()) {
    obj.uv_used = true;
    obj.uv_rows.resize(corner, -1);
    obj.uv_rows.push_back(attribute_row(t, obj.uv.size() / 3, "texture coordinate", in));
  }
  if (!n.empty()) {
    obj.normal_used = true;
    obj.normal_rows.resize(corner, -1);
    obj.normal_rows.push_back(attribute_row(n, obj.normal.size() / 3, "normal", in));
  }
}

// vt, vn, usemtl, mtllib, g, o, s; the statements no channel holds are counted.
void attribute_statement(TextScanner& in, ObjStatements& statement, PolygonSoup& soup, ObjAttributes& obj) {
  const std::string_view head = in.lookahead(8);
  const std::string_view keyword = head.substr(0, head.find_first_of(" \t\r\n\\"));
  auto numbers = [&](std::vector<double>& out, int most, const char* what) {
    statement.token();  // the keyword
    int count = 0;
    for (std::string_view tok = statement.token(); !tok.empty(); tok = statement.token()) {
      if (count == most) in.error(fmt::format("more than {} values in a {} statement", most, what));
      out.push_back(in.to_double(tok, what));
      ++count;
    }
    if (count == 0) in.error(fmt::format("a {} statement without values", what));
    for (int k = count; k < 3; ++k) out.push_back(0);
    return count;
  };
  auto start_label = [&](bool& has, std::vector<double>& values, double none) {
    if (!has) values.assign(static_cast<std::size_t>(soup.num_polygons()), none);
    has = true;
  };
  if (keyword == "vt") {
    obj.uv_width = std::max(obj.uv_width, numbers(obj.uv, 3, "vt"));
  } else if (keyword == "vn") {
    if (numbers(obj.normal, 3, "vn") != 3) in.error("a vn statement needs three values");
  } else if (keyword == "usemtl") {
    statement.token();
    start_label(obj.has_material, obj.material, -1);
    obj.current_material = name_index(soup.attributes.materials, rest_of_statement(statement));
  } else if (keyword == "g") {
    statement.token();
    start_label(obj.has_group, obj.group, -1);
    obj.current_group = name_index(soup.attributes.groups, rest_of_statement(statement));
  } else if (keyword == "o") {
    statement.token();
    start_label(obj.has_object, obj.object, -1);
    obj.current_object = name_index(soup.attributes.objects, rest_of_statement(statement));
  } else if (keyword == "s") {
    statement.token();
    start_label(obj.has_smoothing, obj.smoothing, 0);
    const std::string value = rest_of_statement(statement);
    // "s off" and "s 0" are no group; a value that is no number ("s on") is group 1.
    int group = 1;
    const auto [ptr, ec] = std::from_chars(value.data(), value.data() + value.size(), group);
    if (ec != std::errc() || ptr != value.data() + value.size()) group = value == "off" || value.empty() ? 0 : 1;
    obj.current_smoothing = group;
  } else if (keyword == "mtllib") {
    statement.token();
    const std::string names = rest_of_statement(statement);
    if (!names.empty()) soup.attributes.material_libraries.push_back(names);
  } else {
    count_skipped_statement(head, soup);
  }
}

void finish_attributes(ObjAttributes& obj, PolygonSoup& soup, const std::string& name) {
  MeshAttributes& out = soup.attributes;
  auto corner_channel = [&](const char* channel_name, std::vector<std::string> components, AttributeRole role,
                            const std::vector<double>& values, int stride, int width, std::vector<std::int32_t>& rows,
                            const char* what) {
    const auto count = static_cast<Eigen::Index>(values.size() / static_cast<std::size_t>(stride));
    if (count == 0) {  // indices into a table the file does not have (some exporters): ignored
      soup.count_not_kept(
          fmt::format("OBJ {} indices without any {} statement", what,
                      std::string_view(what) == "normal" ? "vn" : "vt"),
          static_cast<std::int64_t>(std::count_if(rows.begin(), rows.end(), [](std::int32_t r) { return r >= 0; })));
      return;
    }
    for (const std::int32_t r : rows)
      if (r >= count)
        fail(name, fmt::format("a face uses {} {}, but the file has {}", what, std::int64_t{r} + 1, count));
    CornerChannel& c = out.corner.emplace_back();
    c.channel.name = channel_name;
    components.resize(static_cast<std::size_t>(width));
    c.channel.components = std::move(components);
    c.channel.type = ScalarType::Float64;
    c.channel.role = role;
    c.channel.values.resize(count, width);
    for (Eigen::Index r = 0; r < count; ++r)
      for (int k = 0; k < width; ++k) c.channel.values(r, k) = values[static_cast<std::size_t>(r * stride + k)];
    rows.resize(soup.corners.size(), -1);
    soup.corner_rows.push_back(std::move(rows));
  };
  if (!obj.uv.empty() || obj.uv_used)
    corner_channel("uv", {"u", "v", "w"}, AttributeRole::TexCoord, obj.uv, 3, std::max(obj.uv_width, 1), obj.uv_rows,
                   "texture coordinate");
  if (obj.normal_used || !obj.normal.empty())
    corner_channel("normal", {"nx", "ny", "nz"}, AttributeRole::Normal, obj.normal, 3, 3, obj.normal_rows, "normal");
  auto label = [&](const char* channel_name, std::vector<double>& values, bool used, double none) {
    if (!used) return;
    values.resize(static_cast<std::size_t>(soup.num_polygons()), none);
    out.face.push_back(make_channel(channel_name, {channel_name}, ScalarType::Int32, AttributeRole::Label, {values}));
  };
  label("object", obj.object, obj.has_object, -1);
  label("group", obj.group, obj.has_group, -1);
  label("material", obj.material, obj.has_material, -1);
  // "s off" alone (Blender writes it before every object) is the default: no channel of zeros.
  const bool any_smoothing = std::any_of(obj.smoothing.begin(), obj.smoothing.end(), [](double g) { return g != 0; }) ||
                             obj.current_smoothing != 0;
  label("smoothing", obj.smoothing, obj.has_smoothing && any_smoothing, 0);
}

}  // namespace

PolygonSoup parse_obj(ByteSource& source, const std::string& name) {
  PolygonSoup soup;
  soup.index_base = 1;
  TextScanner in(source, name);
  ObjStatements statement(in);
  ObjAttributes obj;
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
        attribute_statement(in, statement, soup, obj);
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
        if (ptr != tok.data() + tok.size()) [[unlikely]]
          corner_attributes(tok.substr(static_cast<std::size_t>(ptr - tok.data()) + 1), soup, obj, in);
      }
      soup.end_polygon();
      if (obj.has_object) obj.object.push_back(obj.current_object);
      if (obj.has_group) obj.group.push_back(obj.current_group);
      if (obj.has_material) obj.material.push_back(obj.current_material);
      if (obj.has_smoothing) obj.smoothing.push_back(obj.current_smoothing);
    }
    statement.end();
  }
  finish_attributes(obj, soup, name);
  return soup;
}

}  // namespace vertexflow::io_detail
