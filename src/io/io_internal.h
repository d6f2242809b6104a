// Internal pieces shared by the readers and writers. Not installed.
#pragma once

#include "byte_source.h"
#include "vertexflow/io.h"

#include <charconv>
#include <cstdint>
#include <cstring>
#include <memory>
#include <string>
#include <string_view>
#include <unordered_set>
#include <vector>

namespace vertexflow::io_detail {

/// What a parser produces: vertices and polygons exactly as the file lists them.
struct PolygonSoup {
  std::vector<double> xyz;               // 3 per vertex
  std::vector<Index> corners;            // polygon corners, concatenated
  std::vector<std::int64_t> offsets{0};  // polygon p is corners[offsets[p], offsets[p+1])
  std::vector<std::uint8_t> rgb;         // empty or 3 per vertex (OFF colours)
  // Channels as the file has them: vertex channels one row per vertex, face channels one row
  // per polygon, corner channels their own table, indexed by corner_rows.
  MeshAttributes attributes;
  // Per corner channel, the row each corner uses (-1 none), parallel to `corners`.
  std::vector<std::vector<std::int32_t>> corner_rows;
  std::vector<std::string> comments;  // Mesh::comments, bounded by add_comment
  // What the file holds that the mesh does not keep, with counts (ReadReport::not_kept).
  std::vector<std::pair<std::string, std::int64_t>> not_kept;
  bool weld_vertices = false;  // STL: facets carry their own vertex copies
  int index_base = 0;          // how the file numbers vertices (OBJ: 1), for messages

  [[nodiscard]] std::int64_t num_vertices() const { return static_cast<std::int64_t>(xyz.size() / 3); }
  [[nodiscard]] std::int64_t num_polygons() const { return static_cast<std::int64_t>(offsets.size()) - 1; }
  void add_vertex(double x, double y, double z) {
    xyz.push_back(x);
    xyz.push_back(y);
    xyz.push_back(z);
  }
  void end_polygon() { offsets.push_back(static_cast<std::int64_t>(corners.size())); }
  // Counts one more of `what` in not_kept.
  void count_not_kept(std::string_view what, std::int64_t count = 1) {
    for (auto& [name, n] : not_kept)
      if (name == what) {
        n += count;
        return;
      }
    not_kept.emplace_back(what, count);
  }
};

/// Throws IoError("name: message").
[[noreturn]] void fail(const std::string& name, const std::string& message);

/// A channel of `columns.size()` components from per-component value columns of equal length.
AttributeChannel make_channel(std::string name, std::vector<std::string> components, ScalarType type,
                              AttributeRole role, const std::vector<std::vector<double>>& columns);

/// How consecutive scalar properties of one element group into channels: "red green blue
/// [alpha]" into a Color channel "color", "nx ny nz" into a Normal channel "normal", "s t",
/// "u v", "texture_u texture_v" into a TexCoord channel "uv"; any other property is a channel
/// of its own (role Label for integer types, Generic for floats). `names` and `types` are the
/// element's scalar properties in file order; returns, per property, its channel's index and
/// component, and the channels without values.
struct ChannelLayout {
  std::vector<AttributeChannel> channels;
  std::vector<std::pair<int, int>> slot;  // per property: (channel, component)
};
ChannelLayout group_properties(const std::vector<std::string>& names, const std::vector<ScalarType>& types);

/// Adds the comment whose text (after the marker) starts `line` to `comments`, as io.h says:
/// cut at the first newline and to kMaxCommentBytes, blanks trimmed, control characters
/// replaced, empty ones and the writers' stamp dropped, nothing once kMaxCommentLines are kept.
void add_comment(std::vector<std::string>& comments, std::string_view line);

/// The writers' own first comment, which every write adds and reading drops.
inline constexpr std::string_view kWriterStamp = "written by vertexflow";

// Parsers: bytes -> soup, pulling from the source only what they read. Each throws IoError
// naming `name`.
PolygonSoup parse_obj(ByteSource& source, const std::string& name);
PolygonSoup parse_ply(ByteSource& source, const std::string& name, ReadReport& report);
PolygonSoup parse_off(ByteSource& source, const std::string& name, ReadReport& report);
PolygonSoup parse_stl(ByteSource& source, const std::string& name, ReadReport& report);

/// Whether `bytes` is exactly as long as the binary STL its header describes (80-byte comment,
/// uint32 triangle count, 50 bytes per triangle): how a binary STL is recognised.
bool has_binary_stl_size(std::string_view bytes);

/// Validates the soup and turns it into a clean triangle mesh (see io.h for what is removed).
Mesh soup_to_mesh(PolygonSoup&& soup, const std::string& name, ReadReport& report, const ReadOptions& options);

/// Undirected edges of a polygon mesh, to keep quad diagonals from duplicating an edge.
using EdgeSet = std::unordered_set<std::uint64_t>;
inline std::uint64_t edge_key(Index a, Index b) {
  if (a > b) std::swap(a, b);
  return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) | static_cast<std::uint32_t>(b);
}

/// Triangulates one polygon (corner indices into xyz) and appends triangles to `out`
/// (3 indices each). `edges` holds the mesh's edges so far: a quad prefers a diagonal that is
/// not already an edge (otherwise two folded quads can produce the same triangle twice), and
/// the chosen diagonal is added. Returns false if it had to fall back to a fan because the
/// polygon has no valid triangulation in its best-fit plane (self-intersecting, folded or
/// degenerate).
bool triangulate_polygon(const double* xyz, const Index* corners, std::size_t count, EdgeSet& edges,
                         std::vector<Index>& out);

/// True for data starting with the gzip magic bytes.
inline bool has_gzip_magic(std::string_view bytes) {
  return bytes.size() >= 2 && static_cast<unsigned char>(bytes[0]) == 0x1f &&
         static_cast<unsigned char>(bytes[1]) == 0x8b;
}

/// Byte order helpers for binary formats.
inline bool host_is_little_endian() {
  const std::uint16_t one = 1;
  unsigned char first = 0;
  std::memcpy(&first, &one, 1);
  return first == 1;
}

template <class T>
T load_scalar(const char* p, bool swap) {
  unsigned char bytes[sizeof(T)];
  std::memcpy(bytes, p, sizeof(T));
  if (swap) {
    for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(bytes[i], bytes[sizeof(T) - 1 - i]);
  }
  T value;
  std::memcpy(&value, bytes, sizeof(T));
  return value;
}

template <class T>
void store_scalar(std::string& out, T value, bool swap) {
  unsigned char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  if (swap) {
    for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(bytes[i], bytes[sizeof(T) - 1 - i]);
  }
  out.append(reinterpret_cast<const char*>(bytes), sizeof(T));
}

/// Appends the shortest decimal text that reads back as exactly `value`.
inline void append_double(std::string& out, double value) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  out.append(buffer, result.ptr);
}

inline void append_int(std::string& out, std::int64_t value) {
  char buffer[24];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  out.append(buffer, result.ptr);
}

/// A cursor over ASCII text that reports errors with the line number. It reads either a
/// fixed view or a ByteSource, which it asks for more bytes when it reaches the end of what is
/// available (and lets drop what it has passed), so text parsers stream through gzip input.
/// Positions are those of the whole content. A token (a string_view) stays valid until the
/// next call on the scanner. Line numbers are counted only when an error is reported.
class TextScanner {
 public:
  TextScanner(std::string_view text, const std::string& name) : text_(text), name_(name) {}
  TextScanner(ByteSource& source, const std::string& name)
      : source_(&source), text_(source.data()), base_(source.offset()), name_(name) {}

  [[nodiscard]] std::size_t position() const { return base_ + pos_; }
  /// Whether `n` more bytes are available (asking the source for them if needed).
  bool has(std::size_t n = 1) { return pos_ + n <= text_.size() || fill(pos_ + n, pos_); }
  bool at_end() { return !has(); }
  char peek() { return has() ? text_[pos_] : '\0'; }
  /// Up to `n` bytes from the current position (fewer at the end of the input).
  std::string_view lookahead(std::size_t n) {
    has(n);
    return text_.substr(std::min(pos_, text_.size()), n);
  }
  /// An upper bound on the bytes left: exact for plain input, the inflation limit for gzip.
  [[nodiscard]] std::uint64_t remaining_bound() const {
    const std::uint64_t total = source_ ? source_->size_bound() : text_.size();
    return total > position() ? total - position() : 0;
  }
  void advance(std::size_t n) { pos_ += n; }

  /// Skips spaces and tabs (and a '\r'), not newlines.
  void skip_blanks() {
    // The scans run on locals, so that the call to fill() on the cold path does not keep the
    // position in memory on the hot one (reading was 10-25% slower before).
    for (;;) {
      std::size_t p = pos_;
      const char* d = text_.data();
      const std::size_t n = text_.size();
      while (p < n && (d[p] == ' ' || d[p] == '\t' || d[p] == '\r')) ++p;
      pos_ = p;
      if (p < n || !fill(pos_ + 1, pos_)) return;
    }
  }
  /// Skips all whitespace including newlines; with `comments`, also '#' to end of line, and
  /// hands the text of those comments to the sink set by collect_comments.
  void skip_whitespace(bool comments = false) {
    for (;;) {
      std::size_t p = pos_;
      const char* d = text_.data();
      const std::size_t n = text_.size();
      while (p < n && is_space(d[p])) ++p;
      pos_ = p;
      if (p < n) {
        if (!comments || d[p] != '#') return;
        if (comment_sink_ != nullptr) take_comment();
        skip_line();
      } else if (!fill(pos_ + 1, pos_)) {
        return;
      }
    }
  }
  /// Comments skipped by skip_whitespace(true) are added to `sink` (add_comment); nullptr stops.
  void collect_comments(std::vector<std::string>* sink) { comment_sink_ = sink; }
  /// Adds the rest of the current line, after the comment marker at the current position, to
  /// `sink` (add_comment). Does not move: the caller skips the line as it would otherwise.
  void peek_comment(std::vector<std::string>& sink) {
    if (sink.size() < kMaxCommentLines) add_comment(sink, lookahead(kMaxCommentBytes + 2).substr(1));
  }
  /// Moves past the next '\n' (or to the end).
  void skip_line() {
    for (;;) {
      const std::size_t nl = text_.find('\n', pos_);
      if (nl != std::string_view::npos) {
        pos_ = nl + 1;
        return;
      }
      pos_ = std::max(pos_, text_.size());
      if (!fill(pos_ + 1, pos_)) return;
    }
  }
  /// Moves past the next '\n' (or to the end) and returns whether the line's last byte
  /// other than blanks was a backslash: an OBJ line continuation.
  bool skip_line_continued() {
    char last = '\0';  // the last non-blank byte of the line seen so far
    for (;;) {
      const std::size_t nl = text_.find('\n', pos_);
      // Backwards from the line's end (or the view's) over blanks: O(1) for a usual line.
      for (std::size_t p = nl == std::string_view::npos ? text_.size() : nl; p > pos_; --p) {
        const char c = text_[p - 1];
        if (c != ' ' && c != '\t' && c != '\r') {
          last = c;
          break;
        }
      }
      if (nl != std::string_view::npos) {
        pos_ = nl + 1;
        return last == '\\';
      }
      pos_ = std::max(pos_, text_.size());
      if (!fill(pos_ + 1, pos_)) return last == '\\';
    }
  }
  /// Makes error() report the line `lines` before the current one: the first physical line
  /// of a statement continued over `lines` line breaks (OBJ).
  void report_lines_back(std::uint64_t lines) { lines_back_ = lines; }
  bool at_line_end() { return !has() || text_[pos_] == '\n' || text_[pos_] == '#'; }
  /// The next whitespace-delimited token on the current line (empty at the line's end).
  std::string_view token_on_line() {
    skip_blanks();
    return scan_token();
  }
  /// The next token, crossing lines (and comments when `comments`).
  std::string_view token(bool comments = false) {
    skip_whitespace(comments);
    return scan_token();
  }

  /// Parses a number from a token; fails with "expected WHAT".
  double to_double(std::string_view tok, const char* what) const {
    if (!tok.empty() && tok.front() == '+') tok.remove_prefix(1);
    double value = 0;
    const auto [ptr, ec] = std::from_chars(tok.data(), tok.data() + tok.size(), value);
    if (tok.empty() || ptr != tok.data() + tok.size() || (ec != std::errc() && ec != std::errc::result_out_of_range))
      error(std::string("expected ") + what + ", found '" + printable(tok) + "'");
    // from_chars leaves `value` unchanged (0) when the number does not fit a double, so
    // "1e999" used to read as 0. Such a number (overflow, or underflow below the smallest
    // subnormal, which no writer produces) is an error.
    if (ec == std::errc::result_out_of_range)
      error(std::string("number '") + printable(tok) + "' is out of range (reading " + what + ")");
    return value;
  }
  std::int64_t to_int(std::string_view tok, const char* what) const {
    if (!tok.empty() && tok.front() == '+') tok.remove_prefix(1);
    std::int64_t value = 0;
    const auto [ptr, ec] = std::from_chars(tok.data(), tok.data() + tok.size(), value);
    if (tok.empty() || ptr != tok.data() + tok.size() || ec != std::errc())
      error(std::string("expected ") + what + ", found '" + printable(tok) + "'");
    return value;
  }
  double next_double(const char* what, bool comments = false) { return to_double(token(comments), what); }
  std::int64_t next_int(const char* what, bool comments = false) { return to_int(token(comments), what); }

  /// Throws IoError("name: line N: message").
  [[noreturn]] void error(const std::string& message) const;

  static bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f' || c == '\v'; }
  /// At most 40 characters of a token, with control bytes replaced, for error messages.
  static std::string printable(std::string_view tok);

 private:
  // The token starting at the current position; the source keeps its first byte while more
  // bytes are fetched.
  std::string_view scan_token() {
    std::size_t start = pos_;
    for (;;) {
      std::size_t p = pos_;
      const char* d = text_.data();
      const std::size_t n = text_.size();
      while (p < n && !is_space(d[p])) ++p;
      pos_ = p;
      if (p < n) break;
      const std::size_t start_position = base_ + start;
      if (!fill(pos_ + 1, start)) break;
      start = start_position - base_;
    }
    return text_.substr(std::min(start, text_.size()), pos_ - start);
  }

  [[gnu::noinline, gnu::cold]] void take_comment() { peek_comment(*comment_sink_); }

  // Asks the source for bytes up to view index `end`, letting it drop those before view index
  // `keep`; refreshes the view, which may have moved, and the index of the current position.
  [[gnu::noinline, gnu::cold]] bool fill(std::size_t end, std::size_t keep) {
    if (source_ == nullptr) return false;
    const std::size_t position = base_ + pos_;
    const bool ok = source_->request(base_ + end, base_ + keep);
    text_ = source_->data();
    base_ = source_->offset();
    pos_ = position - base_;
    return ok;
  }

  ByteSource* source_ = nullptr;
  std::string_view text_;
  std::size_t base_ = 0;  // position of text_[0] in the content
  const std::string& name_;
  std::size_t pos_ = 0;  // index into text_
  std::uint64_t lines_back_ = 0;
  std::vector<std::string>* comment_sink_ = nullptr;
};

}  // namespace vertexflow::io_detail
