// The bytes of one mesh file, made available as a parser asks for them. Not installed.
//
// Plain bytes are all available at once. A gzip stream is inflated in chunks on demand, so
// - a format's header is checked after the first chunk (5 GiB of zeros named .ply.gz fails
//   after 64 kB, not after inflating 5 GiB);
// - a parser that stops early (an error, or its last declared element) never inflates the rest;
// - a streaming parser's consumed bytes are dropped, so memory is the parsed mesh plus a
//   window, not the inflated text;
// - the inflated size is capped (InflateLimit), so a small file cannot claim gigabytes.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

namespace vertexflow::io_detail {

/// Most bytes a gzip stream may inflate to: max(floor_bytes, ratio x compressed size).
struct InflateLimit {
  double ratio = 32;
  std::uint64_t floor_bytes = std::uint64_t{64} << 20;

  [[nodiscard]] std::uint64_t bytes_for(std::uint64_t compressed_size) const;
};

class ByteSource {
 public:
  /// `bytes` must outlive the source. Data starting with the gzip magic is inflated lazily;
  /// anything else is served as it is. Errors throw IoError naming `name`.
  ByteSource(std::string_view bytes, const std::string& name, const InflateLimit& limit);
  ~ByteSource();
  ByteSource(const ByteSource&) = delete;
  ByteSource& operator=(const ByteSource&) = delete;

  [[nodiscard]] bool is_gzip() const { return inflater_ != nullptr; }

  /// The bytes available now: the content's bytes [offset(), end()). A call to request() or
  /// request_all() may move them, and may drop the bytes before its `keep_from`.
  [[nodiscard]] std::string_view data() const { return {data_, size_}; }
  [[nodiscard]] std::size_t offset() const { return offset_; }
  [[nodiscard]] std::size_t end() const { return offset_ + size_; }

  /// Makes the content's bytes up to position `end` available if the stream has that many, and
  /// returns whether it does. Bytes before position `keep_from` (at most offset() + the bytes
  /// the caller still needs) may be dropped, which keeps memory to a window for a parser that
  /// streams through; positions stay those of the whole content.
  bool request(std::size_t end, std::size_t keep_from) {
    return end <= this->end() || request_more(end, keep_from);  // inline: called per value
  }

  /// Makes every byte from offset() on available (for formats that need the total size, e.g.
  /// binary STL); drops nothing.
  void request_all();

  /// Whether data() reaches the end of the content.
  [[nodiscard]] bool complete() const { return complete_; }

  /// An upper bound on the content's total size: exact once complete(), otherwise the limit.
  [[nodiscard]] std::uint64_t size_bound() const { return complete_ ? end() : limit_bytes_; }

  /// Newlines in the dropped bytes before offset(), so text parsers can number lines.
  [[nodiscard]] std::uint64_t newlines_dropped() const { return newlines_dropped_; }

  /// gzip only: inflates the rest of the stream into a scratch buffer without keeping it, so
  /// a truncated or corrupt stream (bad CRC) is reported even when the parser needed less.
  /// The limit still applies; memory stays constant.
  void verify_rest();

 private:
  struct Inflater;
  bool request_more(std::size_t end, std::size_t keep_from);
  // Inflates until end() >= end or the stream ends, dropping bytes before keep_from when the
  // buffer is full and that frees at least half of it.
  void inflate_until(std::size_t end, std::size_t keep_from);
  [[noreturn]] void too_large() const;

  const std::string& name_;
  std::string_view compressed_;
  std::unique_ptr<Inflater> inflater_;
  const char* data_ = nullptr;
  std::size_t size_ = 0;
  std::size_t offset_ = 0;
  std::uint64_t newlines_dropped_ = 0;
  bool complete_ = true;
  InflateLimit limit_;
  std::uint64_t limit_bytes_ = 0;
};

}  // namespace vertexflow::io_detail
