// PLY reader (ASCII, binary little- and big-endian).
//
// Written here because Debian ships no PLY library (tinyply and happly are not packaged) and
// because the reader must bound its allocations by the file's size: every element count in
// the header is checked against the bytes that follow before anything is reserved.
#include "io_internal.h"

#include <fmt/format.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <atomic>
#include <limits>
#include <optional>

namespace vertexflow::io_detail {
namespace {

using Type = ScalarType;  // PLY's eight types are the attribute model's (attributes.h)

std::optional<Type> parse_type(std::string_view s) {
  if (s == "char" || s == "int8") return Type::Int8;
  if (s == "uchar" || s == "uint8") return Type::UInt8;
  if (s == "short" || s == "int16") return Type::Int16;
  if (s == "ushort" || s == "uint16") return Type::UInt16;
  if (s == "int" || s == "int32") return Type::Int32;
  if (s == "uint" || s == "uint32") return Type::UInt32;
  if (s == "float" || s == "float32") return Type::Float32;
  if (s == "double" || s == "float64") return Type::Float64;
  return std::nullopt;
}

std::size_t type_size(Type t) {
  switch (t) {
    case Type::Int8:
    case Type::UInt8:
      return 1;
    case Type::Int16:
    case Type::UInt16:
      return 2;
    case Type::Int32:
    case Type::UInt32:
    case Type::Float32:
      return 4;
    case Type::Float64:
      return 8;
  }
  return 0;
}

bool is_integer(Type t) {
  return t != Type::Float32 && t != Type::Float64;
}

// One value of type t, converted to R. List counts and indices are read with R = int64 (the
// header check guarantees their types are integers).
template <class R>
R load_as(const char* p, Type t, bool swap) {
  switch (t) {
    case Type::Int8:
      return static_cast<R>(static_cast<std::int8_t>(*p));
    case Type::UInt8:
      return static_cast<R>(static_cast<std::uint8_t>(*p));
    case Type::Int16:
      return static_cast<R>(load_scalar<std::int16_t>(p, swap));
    case Type::UInt16:
      return static_cast<R>(load_scalar<std::uint16_t>(p, swap));
    case Type::Int32:
      return static_cast<R>(load_scalar<std::int32_t>(p, swap));
    case Type::UInt32:
      return static_cast<R>(load_scalar<std::uint32_t>(p, swap));
    case Type::Float32:
      return static_cast<R>(load_scalar<float>(p, swap));
    case Type::Float64:
      return static_cast<R>(load_scalar<double>(p, swap));
  }
  return 0;
}

struct Property {
  std::string name;
  Type type = Type::Float32;
  bool is_list = false;
  Type count_type = Type::UInt8;
};

struct Element {
  std::string name;
  std::uint64_t count = 0;
  std::vector<Property> properties;
};

enum class Encoding { Ascii, BinaryLittle, BinaryBig };

// What each vertex property becomes.
enum class Role { X, Y, Z, Channel, Skip };

class PlyParser {
 public:
  PlyParser(ByteSource& source, const std::string& name, ReadReport& report)
      : source_(source), name_(name), report_(report) {}

  PolygonSoup parse() {
    parse_header();
    for (const Element& element : elements_) {
      if (element.name == "vertex") {
        read_vertices(element);
      } else if (element.name == "face") {
        read_faces(element, /*strips=*/false);
      } else if (element.name == "tristrips") {
        read_faces(element, /*strips=*/true);
      } else {
        skip_element(element);
        if (element.count > 0)
          soup_.count_not_kept("PLY element '" + element.name + "'", static_cast<std::int64_t>(element.count));
      }
    }
    return std::move(soup_);
  }

 private:
  void parse_header() {
    const std::size_t header_end = find_end_header();
    TextScanner header(source_.data().substr(0, header_end), name_);
    if (header.token_on_line() != "ply") fail(name_, "not a PLY file (first line must be 'ply')");
    header.skip_line();
    bool have_format = false;
    while (!header.at_end()) {
      const std::string_view keyword = header.token_on_line();
      if (keyword == "comment") {
        add_comment(soup_.comments, header.lookahead(kMaxCommentBytes + 1));
      } else if (keyword.empty() || keyword == "obj_info") {
      } else if (keyword == "format") {
        const std::string_view format = header.token_on_line();
        if (format == "ascii")
          encoding_ = Encoding::Ascii;
        else if (format == "binary_little_endian")
          encoding_ = Encoding::BinaryLittle;
        else if (format == "binary_big_endian")
          encoding_ = Encoding::BinaryBig;
        else
          header.error("unknown PLY format '" + TextScanner::printable(format) + "'");
        have_format = true;
      } else if (keyword == "element") {
        Element element;
        element.name = std::string(header.token_on_line());
        const std::string_view count = header.token_on_line();
        if (element.name.empty() || count.empty() || count.front() == '-') header.error("malformed element line");
        element.count = static_cast<std::uint64_t>(header.to_int(count, "an element count"));
        // A second 'vertex' element would be read over the first, leaving soup_.rgb and the
        // scalar properties sized for the first one's count (heap overflow in soup_to_mesh).
        if (element.name == "vertex" &&
            std::any_of(elements_.begin(), elements_.end(), [](const Element& e) { return e.name == "vertex"; }))
          header.error("more than one 'vertex' element");
        elements_.push_back(std::move(element));
      } else if (keyword == "property") {
        if (elements_.empty()) header.error("property before any element");
        Property property;
        std::string_view type = header.token_on_line();
        if (type == "list") {
          property.is_list = true;
          const auto count_type = parse_type(header.token_on_line());
          if (!count_type || !is_integer(*count_type)) header.error("list count type must be an integer type");
          property.count_type = *count_type;
          type = header.token_on_line();
        }
        const auto value_type = parse_type(type);
        if (!value_type) header.error("unknown property type '" + TextScanner::printable(type) + "'");
        property.type = *value_type;
        property.name = std::string(header.token_on_line());
        if (property.name.empty()) header.error("property without a name");
        elements_.back().properties.push_back(std::move(property));
      } else if (keyword == "end_header") {
        break;
      } else {
        header.error("unknown header keyword '" + TextScanner::printable(keyword) + "'");
      }
      header.skip_line();
    }
    if (!have_format) fail(name_, "PLY header has no format line");
    report_.binary = encoding_ != Encoding::Ascii;
    swap_ = (encoding_ == Encoding::BinaryBig) == host_is_little_endian();
    if (std::none_of(elements_.begin(), elements_.end(), [](const Element& e) { return e.name == "vertex"; }))
      fail(name_, "PLY header declares no vertex element");
    if (std::none_of(elements_.begin(), elements_.end(),
                     [](const Element& e) { return e.name == "face" || e.name == "tristrips"; }))
      fail(name_, "PLY header declares no face or tristrips element (point clouds are not meshes)");
  }

  // Returns the offset just past the "end_header" line and positions the body there. Reads
  // the header line by line from the source, so a stream that is no PLY fails at once.
  std::size_t find_end_header() {
    source_.request(3, 0);
    if (source_.data().substr(0, 3) != "ply") fail(name_, "not a PLY file (first line must be 'ply')");
    std::size_t pos = 0;
    for (;;) {
      std::size_t nl = source_.data().find('\n', pos);
      while (nl == std::string_view::npos) {
        const std::size_t searched = source_.data().size();
        if (!source_.request(searched + 1, 0)) break;  // the header is kept for parse_header
        nl = source_.data().find('\n', searched);
      }
      const std::string_view bytes = source_.data();
      if (pos >= bytes.size()) break;
      if (nl == std::string_view::npos) nl = bytes.size();
      std::string_view line = bytes.substr(pos, nl - pos);
      if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
      if (line == "end_header" || line.substr(0, 11) == "end_header ") {
        body_ = std::min(nl + 1, bytes.size());
        return body_;
      }
      // A header is text; binary data before end_header means this is no PLY header (or a
      // stream that would make us scan far for a line that never comes).
      if (line.find('\0') != std::string_view::npos) fail(name_, "not a PLY file (binary data in the header)");
      pos = nl + 1;
    }
    fail(name_, "PLY header has no end_header line (truncated file?)");
  }

  // Bytes one record of `element` needs at least; used to reject counts the file cannot hold.
  std::uint64_t min_record_bytes(const Element& element) const {
    std::uint64_t bytes = 0;
    for (const Property& p : element.properties) {
      if (encoding_ == Encoding::Ascii)
        bytes += 2;  // one character and a separator
      else
        bytes += type_size(p.is_list ? p.count_type : p.type);
    }
    return bytes;
  }

  void check_count(const Element& element) const {
    const std::uint64_t min_bytes = min_record_bytes(element);
    const std::uint64_t available = source_.size_bound() - body_;
    // ASCII: the last record needs no trailing separator, hence the extra byte.
    const std::uint64_t capacity =
        min_bytes == 0 ? 0 : (encoding_ == Encoding::Ascii ? available + 1 : available) / min_bytes;
    if (min_bytes > 0 && element.count > capacity)
      fail(name_, fmt::format("header declares {} '{}' elements, but the remaining {} bytes{} can hold at most {}",
                              element.count, element.name, available,
                              source_.complete() ? "" : " (the gzip inflation limit)", capacity));
  }

  // --- value access: ASCII tokens or binary bytes, advancing body_ ---
  double next_value(Type type, const char* what) {
    if (encoding_ == Encoding::Ascii) return ascii_value(what);
    const std::size_t size = type_size(type);
    const double v = load_as<double>(binary_bytes(size, what), type, swap_);
    body_ += size;
    return v;
  }
  std::int64_t next_integer(Type type, const char* what) {
    if (encoding_ == Encoding::Ascii) {
      const double v = ascii_value(what);
      if (v != std::floor(v) || std::abs(v) > 9e15) ascii().error(fmt::format("{} must be an integer", what));
      return static_cast<std::int64_t>(v);
    }
    const std::size_t size = type_size(type);
    const std::int64_t v = load_as<std::int64_t>(binary_bytes(size, what), type, swap_);
    body_ += size;
    return v;
  }
  std::uint64_t next_list_count(const Property& p) {
    const std::int64_t n = next_integer(p.count_type, "list length");
    const std::uint64_t available = source_.size_bound() - position();
    const std::uint64_t item = encoding_ == Encoding::Ascii ? 2 : type_size(p.type);
    if (n < 0 || static_cast<std::uint64_t>(n) > (available + 1) / item)
      fail(name_, fmt::format("invalid list length {} for property '{}' at byte {}", n, p.name, position()));
    return static_cast<std::uint64_t>(n);
  }
  void skip_property(const Property& p) {
    if (!p.is_list) {
      next_value(p.type, "a property value");
      return;
    }
    const std::uint64_t n = next_list_count(p);
    for (std::uint64_t i = 0; i < n; ++i) next_value(p.type, "a list item");
  }
  // The next `size` bytes of a binary body; what lies before them may be dropped.
  const char* binary_bytes(std::size_t size, const char* what) {
    if (!source_.request(body_ + size, body_)) truncated(what);
    return source_.data().data() + (body_ - source_.offset());
  }
  [[noreturn]] void truncated(const char* what) const {
    fail(name_, fmt::format("unexpected end of file while reading {} (file truncated?)", what));
  }
  // ASCII body scanning shares body_ through a scanner positioned at it.
  // ASCII PLY has one element record per line: values are taken from the current line only,
  // so a missing value is an error on its line instead of shifting every later value.
  double ascii_value(const char* what) {
    const std::string_view tok = ascii().token_on_line();
    if (tok.empty()) ascii().error(fmt::format("too few values on the line (expected {})", what));
    return ascii().to_double(tok, what);
  }
  void begin_record() {
    if (encoding_ == Encoding::Ascii) ascii().skip_whitespace();
  }
  void end_record(const Element& element) {
    if (encoding_ != Encoding::Ascii) return;
    ascii().skip_blanks();
    if (ascii().at_end() || ascii().peek() == '\n') return;
    // More values than declared is a common writer bug (e.g. normals or a face colour written
    // but not declared). The declared values were read from the line's start, so they are
    // right; the rest is ignored, and counted. It must still be numbers: anything else is no
    // PLY record.
    for (std::string_view tok = ascii().token_on_line(); !tok.empty(); tok = ascii().token_on_line()) {
      const std::string_view number = tok.substr(tok.front() == '+' ? 1 : 0);  // as to_double reads it
      double value = 0;
      const auto [ptr, ec] = std::from_chars(number.data(), number.data() + number.size(), value);
      if (number.empty() || ptr != number.data() + number.size() ||
          (ec != std::errc() && ec != std::errc::result_out_of_range))
        ascii().error(fmt::format("more values than the '{}' element declares, and '{}' is not a number", element.name,
                                  TextScanner::printable(tok)));
    }
    ++report_.ply_extra_values_lines;
  }
  TextScanner& ascii() {
    if (!scanner_) {
      scanner_.emplace(source_, name_);
      scanner_->advance(body_);
    }
    return *scanner_;
  }

  // A property value to be stored in a channel: exactly what its type holds. ASCII text can
  // hold any number, so an integer property's value must be one its type holds (converting a
  // double outside 0..255, or NaN, to uint8 would be undefined behaviour: found by
  // fuzz_read_ply).
  double channel_value(const Property& p, const char* what) {
    const double value = next_value(p.type, what);
    if (encoding_ != Encoding::Ascii) return value;
    if (is_integer(p.type) && to_scalar_type(value, p.type) != value)
      ascii().error(fmt::format("{} '{}' value {} is not a {}", what, p.name, value, scalar_type_name(p.type)));
    return to_scalar_type(value, p.type);
  }

  // The scalar properties of `element` other than `excluded` as channels (group_properties),
  // with a column of values per property (`columns`) and each property's slot in them (-1 for
  // properties that are no channel).
  ChannelLayout element_channels(const Element& element, const std::vector<char>& excluded,
                                 std::vector<int>& column_of) {
    std::vector<std::string> names;
    std::vector<ScalarType> types;
    column_of.assign(element.properties.size(), -1);
    for (std::size_t i = 0; i < element.properties.size(); ++i) {
      const Property& p = element.properties[i];
      if (p.is_list || excluded[i]) continue;
      column_of[i] = static_cast<int>(names.size());
      names.push_back(p.name);
      types.push_back(p.type);
    }
    return group_properties(names, types);
  }

  // Moves per-property columns into the layout's channels.
  static void fill_channels(ChannelLayout& layout, std::vector<std::vector<double>>& columns,
                            std::vector<AttributeChannel>& out) {
    std::vector<std::vector<std::vector<double>>> per_channel(layout.channels.size());
    for (std::size_t c = 0; c < layout.channels.size(); ++c)
      per_channel[c].resize(layout.channels[c].components.size());
    for (std::size_t i = 0; i < columns.size(); ++i) {
      const auto [channel, component] = layout.slot[i];
      per_channel[static_cast<std::size_t>(channel)][static_cast<std::size_t>(component)] = std::move(columns[i]);
    }
    for (std::size_t c = 0; c < layout.channels.size(); ++c) {
      AttributeChannel& channel = layout.channels[c];
      out.push_back(make_channel(std::move(channel.name), std::move(channel.components), channel.type, channel.role,
                                 per_channel[c]));
    }
  }

  void read_vertices(const Element& element) {
    check_count(element);
    std::vector<Role> roles;
    std::vector<char> coordinate(element.properties.size(), 0);
    bool has[3] = {false, false, false};
    for (std::size_t i = 0; i < element.properties.size(); ++i) {
      const Property& p = element.properties[i];
      Role role = p.is_list ? Role::Skip : Role::Channel;
      if (!p.is_list) {
        for (int axis = 0; axis < 3; ++axis)
          if (p.name == "xyz"[axis] + std::string() && !has[axis]) {
            role = static_cast<Role>(axis);
            has[axis] = true;
            coordinate[i] = 1;
          }
      }
      roles.push_back(role);
    }
    if (!has[0] || !has[1] || !has[2]) fail(name_, "vertex element lacks an x, y or z property");
    std::vector<int> column_of;
    ChannelLayout layout = element_channels(element, coordinate, column_of);
    // The count is bounded by the bytes the input can hold (check_count; for gzip, by the
    // inflation limit). Reserved pages become resident only as records fill them, so a gzip
    // header's claim costs address space, not memory, until the content backs it.
    const std::uint64_t n = element.count;
    const auto expected = static_cast<std::size_t>(n);
    std::vector<std::vector<double>> columns(layout.slot.size());
    if (const char* records = fixed_records(element, n)) {
      decode_vertices(element, roles, column_of, records, expected, columns);
    } else {
      soup_.xyz.reserve(3 * expected);
      for (auto& column : columns) column.reserve(expected);
      read_vertex_records(element, roles, column_of, n, columns);
    }
    for (std::size_t i = 0; i < element.properties.size(); ++i)
      if (roles[i] == Role::Skip && n > 0)
        soup_.count_not_kept("PLY vertex list property '" + element.properties[i].name + "'",
                             static_cast<std::int64_t>(n));
    fill_channels(layout, columns, soup_.attributes.vertex);
    sync_ascii();
  }

  // The vertex records one by one, through the value access below (any encoding).
  void read_vertex_records(const Element& element, const std::vector<Role>& roles, const std::vector<int>& column_of,
                           std::uint64_t n, std::vector<std::vector<double>>& columns) {
    for (std::uint64_t v = 0; v < n; ++v) {
      begin_record();
      double xyz[3] = {0, 0, 0};
      for (std::size_t i = 0; i < element.properties.size(); ++i) {
        const Property& p = element.properties[i];
        switch (roles[i]) {
          case Role::X:
          case Role::Y:
          case Role::Z:
            xyz[static_cast<std::size_t>(roles[i])] = next_value(p.type, "a vertex coordinate");
            break;
          case Role::Channel:
            columns[static_cast<std::size_t>(column_of[i])].push_back(channel_value(p, "vertex property"));
            break;
          case Role::Skip:
            skip_property(p);
            break;
        }
      }
      soup_.add_vertex(xyz[0], xyz[1], xyz[2]);
      end_record(element);
    }
  }

  // The n records of a binary element whose properties are all scalars (so each record has the
  // same size), when they are all in memory: the bytes of the first, else null (then the
  // records are read one by one).
  const char* fixed_records(const Element& element, std::uint64_t n) {
    for (const Property& p : element.properties)
      if (p.is_list) return nullptr;
    return n == 0 ? nullptr : records_in_memory(n * record_size(element));
  }
  // The next `bytes` bytes of a binary body when the whole content is in memory (a plain file)
  // and holds them, else null: then the one-by-one read reports where the content ends.
  const char* records_in_memory(std::uint64_t bytes) const {
    if (encoding_ == Encoding::Ascii || !source_.complete() || body_ + bytes > source_.end()) return nullptr;
    return source_.data().data() + (body_ - source_.offset());
  }
  static std::size_t record_size(const Element& element) {
    std::size_t size = 0;
    for (const Property& p : element.properties) size += type_size(p.type);
    return size;
  }

  // read_vertex_records' values from fixed records, decoded on all threads: each value is
  // load_as<double>'s of its bytes, as next_value and channel_value give it for binary files.
  // A 54 MB file of 1M vertices and 2M faces spent most of its 0.07 s parse in the
  // value-by-value reads.
  void decode_vertices(const Element& element, const std::vector<Role>& roles, const std::vector<int>& column_of,
                       const char* records, std::size_t n, std::vector<std::vector<double>>& columns) {
    const std::size_t size = record_size(element), first = soup_.xyz.size();
    soup_.xyz.resize(first + 3 * n);
    for (auto& column : columns) column.resize(n);
    std::vector<std::size_t> offset(element.properties.size(), 0);
    for (std::size_t i = 1; i < offset.size(); ++i)
      offset[i] = offset[i - 1] + type_size(element.properties[i - 1].type);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 16384), [&](const tbb::blocked_range<std::size_t>& range) {
      for (std::size_t v = range.begin(); v != range.end(); ++v) {
        const char* record = records + v * size;
        for (std::size_t i = 0; i < element.properties.size(); ++i) {
          const double value = load_as<double>(record + offset[i], element.properties[i].type, swap_);
          if (roles[i] == Role::Channel)
            columns[static_cast<std::size_t>(column_of[i])][v] = value;
          else
            soup_.xyz[first + 3 * v + static_cast<std::size_t>(roles[i])] = value;
        }
      }
    });
    body_ += n * size;
  }

  // A face element of triangles only, as scanners and most tools write it (a one-byte count of
  // 3 and three 4-byte indices per record, nothing else), decoded on all threads when it is all
  // in memory. Returns false, having read nothing, for any other layout or count: the records
  // are then read one by one. An invalid index fails with the message of the one-by-one read,
  // for the first face that has one.
  bool decode_triangles(const Element& element) {
    if (element.count == 0 || element.properties.size() != 1) return false;
    const Property& p = element.properties[0];
    if (type_size(p.count_type) != 1 || (p.type != Type::Int32 && p.type != Type::UInt32)) return false;
    constexpr std::size_t kRecord = 13;
    const auto n = static_cast<std::size_t>(element.count);
    const char* records = records_in_memory(n * kRecord);
    if (records == nullptr) return false;
    const bool all_triangles = tbb::parallel_reduce(
        tbb::blocked_range<std::size_t>(0, n, 65536), true,
        [&](const tbb::blocked_range<std::size_t>& range, bool ok) {
          for (std::size_t f = range.begin(); ok && f != range.end(); ++f) ok = records[f * kRecord] == 3;
          return ok;
        },
        [](bool a, bool b) { return a && b; });
    if (!all_triangles) return false;
    const std::size_t first_corner = soup_.corners.size(), first_polygon = soup_.offsets.size();
    soup_.corners.resize(first_corner + 3 * n);
    soup_.offsets.resize(first_polygon + n);
    auto index_at = [&](std::size_t f, std::size_t k) {
      return load_as<std::int64_t>(records + f * kRecord + 1 + 4 * k, p.type, swap_);
    };
    auto valid = [](std::int64_t index) { return index >= 0 && index <= std::numeric_limits<Index>::max(); };
    std::atomic<std::size_t> first_invalid{n};
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 16384), [&](const tbb::blocked_range<std::size_t>& range) {
      for (std::size_t f = range.begin(); f != range.end(); ++f) {
        for (std::size_t k = 0; k < 3; ++k) {
          const std::int64_t index = index_at(f, k);
          if (!valid(index)) {
            std::size_t seen = first_invalid.load(std::memory_order_relaxed);
            while (f < seen && !first_invalid.compare_exchange_weak(seen, f, std::memory_order_relaxed)) {
            }
          }
          soup_.corners[first_corner + 3 * f + k] = static_cast<Index>(index);
        }
        soup_.offsets[first_polygon + f] = static_cast<std::int64_t>(first_corner + 3 * (f + 1));
      }
    });
    if (const std::size_t f = first_invalid.load(); f < n)
      for (std::size_t k = 0; k < 3; ++k)
        if (!valid(index_at(f, k)))
          fail(name_, fmt::format("{} {} has invalid vertex index {}", element.name, f, index_at(f, k)));
    body_ += n * kRecord;
    return true;
  }

  // A `face` element (one polygon per record), or a `tristrips` element (Cyberware and Stanford
  // scans: one or more strips per record, separated by -1; triangle i of a strip is corners
  // (i, i+1, i+2), every other one turned round to keep the strip's orientation). A face
  // element's scalar properties become face channels, and a float list `texcoord` (MeshLab's
  // per-corner texture coordinates, two per corner) a corner channel.
  void read_faces(const Element& element, bool strips) {
    check_count(element);
    std::size_t index_property = element.properties.size();
    std::size_t texcoord_property = element.properties.size();
    for (std::size_t i = 0; i < element.properties.size(); ++i) {
      const Property& p = element.properties[i];
      if (p.is_list && (p.name == "vertex_indices" || p.name == "vertex_index") &&
          index_property == element.properties.size())
        index_property = i;
      else if (!strips && p.is_list && p.name == "texcoord" && !is_integer(p.type))
        texcoord_property = i;
    }
    if (index_property == element.properties.size())
      fail(name_, element.name + " element has no 'vertex_indices' list property");
    if (!is_integer(element.properties[index_property].type))
      fail(name_, element.name + " vertex indices must have an integer type");
    if (!strips && decode_triangles(element)) return;
    const std::uint64_t n = element.count;
    const auto expected = static_cast<std::size_t>(n);  // bounded as in read_vertices
    if (!strips) {
      soup_.offsets.reserve(expected + 1);
      soup_.corners.reserve(3 * expected);
    }
    // Strips carry no face data we keep: their triangles are not the element's records.
    std::vector<char> excluded(element.properties.size(), strips ? 1 : 0);
    excluded[index_property] = 1;
    std::vector<int> column_of;
    ChannelLayout layout = element_channels(element, excluded, column_of);
    std::vector<std::vector<double>> columns(layout.slot.size());
    for (auto& column : columns) column.reserve(expected);
    std::vector<double> texcoords;  // two per corner
    std::vector<Index> strip;
    const std::size_t first_polygon = static_cast<std::size_t>(soup_.num_polygons());
    for (std::uint64_t f = 0; f < n; ++f) {
      begin_record();
      std::size_t polygon_corners = 0, polygon_texcoords = 0;
      for (std::size_t i = 0; i < element.properties.size(); ++i) {
        const Property& p = element.properties[i];
        if (column_of[i] >= 0) {
          columns[static_cast<std::size_t>(column_of[i])].push_back(channel_value(p, "face property"));
          continue;
        }
        if (i == texcoord_property) {
          const std::uint64_t count = next_list_count(p);
          for (std::uint64_t k = 0; k < count; ++k)
            texcoords.push_back(to_scalar_type(next_value(p.type, "a texture coordinate"), p.type));
          polygon_texcoords = static_cast<std::size_t>(count);
          continue;
        }
        if (i != index_property) {
          skip_property(p);
          continue;
        }
        const std::uint64_t count = next_list_count(p);
        strip.clear();
        for (std::uint64_t k = 0; k < count; ++k) {
          const std::int64_t index = next_integer(p.type, "a face vertex index");
          // -1 ends a strip (as uint32, some writers' 4294967295).
          if (strips && (index == -1 || (p.type == Type::UInt32 && index == 4294967295))) {
            end_strip(strip);
            continue;
          }
          if (index < 0 || index > std::numeric_limits<Index>::max())
            fail(name_, fmt::format("{} {} has invalid vertex index {}", element.name, f, index));
          if (strips)
            strip.push_back(static_cast<Index>(index));
          else
            soup_.corners.push_back(static_cast<Index>(index));
        }
        polygon_corners = static_cast<std::size_t>(count);
        if (strips) end_strip(strip);
      }
      if (texcoord_property < element.properties.size() && polygon_texcoords != 2 * polygon_corners)
        fail(name_, fmt::format("face {} has {} texcoord values for {} corners (expected two per corner)", f,
                                polygon_texcoords, polygon_corners));
      if (!strips) soup_.end_polygon();
      end_record(element);
    }
    for (std::size_t i = 0; i < element.properties.size(); ++i)
      if (i != index_property && i != texcoord_property && column_of[i] < 0 && n > 0)
        soup_.count_not_kept("PLY " + element.name + " property '" + element.properties[i].name + "'",
                             static_cast<std::int64_t>(n));
    if (!strips) {
      // Face channels have a row per polygon of the soup; polygons read before this element
      // (a file with two face elements) get zeros.
      std::vector<AttributeChannel> channels;
      fill_channels(layout, columns, channels);
      for (AttributeChannel& channel : channels) {
        if (first_polygon > 0) {
          Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> padded =
              Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(first_polygon) + channel.rows(), channel.width());
          padded.bottomRows(channel.rows()) = channel.values;
          channel.values = std::move(padded);
        }
        soup_.attributes.face.push_back(std::move(channel));
      }
      if (texcoord_property < element.properties.size()) {
        const Property& p = element.properties[texcoord_property];
        CornerChannel& corner = soup_.attributes.corner.emplace_back();
        corner.channel.name = p.name;
        corner.channel.components = {"u", "v"};
        corner.channel.type = p.type;
        corner.channel.role = AttributeRole::TexCoord;
        corner.channel.values = Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::RowMajor>>(
            texcoords.data(), static_cast<Eigen::Index>(texcoords.size() / 2), 2);
        // Corner c of this element's polygons uses row c; earlier polygons' corners have none.
        std::vector<std::int32_t>& rows = soup_.corner_rows.emplace_back(soup_.corners.size(), -1);
        const std::size_t first_corner = soup_.corners.size() - texcoords.size() / 2;
        for (std::size_t c = first_corner; c < rows.size(); ++c) rows[c] = static_cast<std::int32_t>(c - first_corner);
      }
    }
    sync_ascii();
  }

  // The triangles of one strip, then an empty strip. A triangle with a repeated corner is how
  // strips turn or jump (stitching), not a face: skipped.
  void end_strip(std::vector<Index>& strip) {
    for (std::size_t i = 2; i < strip.size(); ++i) {
      const Index a = strip[i - 2], b = strip[i - 1], c = strip[i];
      if (a == b || b == c || c == a) continue;
      if (i % 2 == 0) {
        soup_.corners.insert(soup_.corners.end(), {a, b, c});
      } else {
        soup_.corners.insert(soup_.corners.end(), {b, a, c});
      }
      soup_.end_polygon();
      ++report_.strip_triangles;
    }
    strip.clear();
  }

  void skip_element(const Element& element) {
    check_count(element);
    if (element.properties.empty()) return;
    for (std::uint64_t r = 0; r < element.count; ++r) {
      begin_record();
      for (const Property& p : element.properties) skip_property(p);
      end_record(element);
    }
    sync_ascii();
  }

  std::size_t position() const { return scanner_ ? scanner_->position() : body_; }

  // After an ASCII element, keep body_ in step with the scanner (used by the count checks).
  void sync_ascii() {
    if (scanner_) body_ = scanner_->position();
  }

  ByteSource& source_;
  const std::string& name_;
  ReadReport& report_;
  std::vector<Element> elements_;
  Encoding encoding_ = Encoding::Ascii;
  bool swap_ = false;
  std::size_t body_ = 0;
  std::optional<TextScanner> scanner_;
  PolygonSoup soup_;
};

}  // namespace

PolygonSoup parse_ply(ByteSource& source, const std::string& name, ReadReport& report) {
  return PlyParser(source, name, report).parse();
}

}  // namespace vertexflow::io_detail
