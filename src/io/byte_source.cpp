#include "byte_source.h"

#include "io_internal.h"

#include <fmt/format.h>
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>

namespace vertexflow::io_detail {

std::uint64_t InflateLimit::bytes_for(std::uint64_t compressed_size) const {
  const double by_ratio = ratio * static_cast<double>(compressed_size);
  // Doubles above 2^63 do not convert; such a limit is no limit.
  const std::uint64_t ratio_bytes =
      by_ratio >= 4.6e18 ? std::uint64_t{1} << 62 : static_cast<std::uint64_t>(std::max(by_ratio, 0.0));
  return std::max(floor_bytes, ratio_bytes);
}

// The zlib state and the buffer of inflated bytes. The buffer grows with realloc, which for
// large blocks remaps pages instead of copying them, and is never zero-filled: pages become
// resident only as inflate writes them.
struct ByteSource::Inflater {
  z_stream stream{};
  char* buffer = nullptr;
  std::size_t capacity = 0;
  std::size_t consumed = 0;  // compressed bytes read so far
  bool stream_ended = false;

  ~Inflater() {
    inflateEnd(&stream);
    std::free(buffer);
  }

  // One call of inflate() from compressed[consumed..] into out[0, out_size). Returns the bytes
  // written and sets stream_ended at the end of the last gzip member. Throws on bad data.
  std::size_t step(std::string_view compressed, char* out, std::size_t out_size, const std::string& name) {
    const std::size_t in_chunk = std::min<std::size_t>(compressed.size() - consumed, 1u << 30);
    const std::size_t out_chunk = std::min<std::size_t>(out_size, 1u << 30);
    stream.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(compressed.data() + consumed));
    stream.avail_in = static_cast<uInt>(in_chunk);
    stream.next_out = reinterpret_cast<Bytef*>(out);
    stream.avail_out = static_cast<uInt>(out_chunk);
    const int rc = inflate(&stream, Z_NO_FLUSH);
    consumed += in_chunk - stream.avail_in;
    const std::size_t produced = out_chunk - stream.avail_out;
    if (rc == Z_STREAM_END) {
      // Concatenated members (as `cat a.gz b.gz` makes) continue the same content; any other
      // trailing bytes are ignored, as gzip itself does with trailing zeros.
      if (consumed < compressed.size() && has_gzip_magic(compressed.substr(consumed)))
        inflateReset(&stream);
      else
        stream_ended = true;
    } else if (rc == Z_BUF_ERROR && consumed == compressed.size()) {
      fail(name, "truncated gzip data");
    } else if (rc != Z_OK && rc != Z_BUF_ERROR) {
      fail(name, std::string("invalid gzip data (") + (stream.msg ? stream.msg : "corrupt data") + ")");
    }
    return produced;
  }
};

ByteSource::ByteSource(std::string_view bytes, const std::string& name, const InflateLimit& limit)
    : name_(name), data_(bytes.data()), size_(bytes.size()) {
  if (!has_gzip_magic(bytes)) return;
  compressed_ = bytes;
  data_ = nullptr;
  size_ = 0;
  complete_ = false;
  limit_ = limit;
  limit_bytes_ = limit.bytes_for(bytes.size());
  inflater_ = std::make_unique<Inflater>();
  // 16 + MAX_WBITS: expect a gzip header.
  if (inflateInit2(&inflater_->stream, 16 + MAX_WBITS) != Z_OK) {
    inflater_.reset();  // nothing to end
    fail(name_, "cannot initialise the gzip decoder");
  }
}

ByteSource::~ByteSource() = default;

bool ByteSource::request_more(std::size_t end, std::size_t keep_from) {
  if (!complete_) inflate_until(end, keep_from);
  return end <= this->end();
}

void ByteSource::request_all() {
  while (!complete_) inflate_until(end() + 1, offset_);
}

void ByteSource::too_large() const {
  fail(name_, fmt::format("gzip data inflates to more than {} bytes, the limit for {} compressed bytes "
                          "({:g} times as many, at least {} MiB; a decompression bomb?); set "
                          "VERTEXFLOW_MAX_INFLATE_RATIO to raise it",
                          limit_bytes_, compressed_.size(), limit_.ratio, limit_.floor_bytes >> 20));
}

void ByteSource::inflate_until(std::size_t end, std::size_t keep_from) {
  Inflater& z = *inflater_;
  // Chunks large enough that zlib's per-call cost vanishes, small enough to stay in cache.
  constexpr std::size_t kFirstChunk = std::size_t{256} << 10;
  keep_from = std::clamp(keep_from, offset_, this->end());
  while (this->end() < end && !complete_) {
    if (size_ == z.capacity) {
      const std::size_t droppable = keep_from - offset_;
      if (droppable > 0 && droppable >= z.capacity / 2) {
        newlines_dropped_ += static_cast<std::uint64_t>(std::count(z.buffer, z.buffer + droppable, '\n'));
        std::memmove(z.buffer, z.buffer + droppable, size_ - droppable);
        size_ -= droppable;
        offset_ += droppable;
      } else {
        // One byte past the limit tells a stream of exactly `limit` bytes from a longer one.
        const std::uint64_t most = limit_bytes_ + 1 - offset_;
        const std::size_t wanted = static_cast<std::size_t>(
            std::min<std::uint64_t>(std::max({kFirstChunk, 2 * z.capacity, end - offset_}), most));
        if (wanted <= z.capacity) too_large();
        char* grown = static_cast<char*>(std::realloc(z.buffer, wanted));
        if (grown == nullptr) fail(name_, fmt::format("out of memory inflating gzip data ({} bytes)", wanted));
        z.buffer = grown;
        z.capacity = wanted;
      }
    }
    size_ += z.step(compressed_, z.buffer + size_, z.capacity - size_, name_);
    data_ = z.buffer;
    if (this->end() > limit_bytes_) too_large();
    complete_ = z.stream_ended;
  }
}

void ByteSource::verify_rest() {
  if (!inflater_ || complete_) return;
  Inflater& z = *inflater_;
  std::unique_ptr<char[]> scratch(new char[std::size_t{1} << 16]);
  std::uint64_t total = end();
  while (!z.stream_ended) {
    total += z.step(compressed_, scratch.get(), std::size_t{1} << 16, name_);
    if (total > limit_bytes_) too_large();
  }
}

}  // namespace vertexflow::io_detail
