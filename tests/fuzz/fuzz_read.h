// Shared body of the libFuzzer targets: read arbitrary bytes as one mesh format.
//
// The only acceptable failure is vertexflow::IoError with a one-line message starting with
// the name. Any other exception escapes and libFuzzer reports it (as an uncaught exception,
// i.e. an abort); crashes, leaks and undefined behaviour are caught by the sanitizers.
#pragma once

#include "vertexflow/io.h"

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>

namespace vertexflow::fuzz {

inline int read_one(const std::uint8_t* data, std::size_t size, MeshFormat format) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  ReadOptions options;
  // Keep gzip inputs from inflating to gigabytes: scripts/fuzz.sh runs with
  // -malloc_limit_mb=512, so that any single allocation that large (from at most 64 kB of input,
  // or 16 MB once inflated) is reported as a header count that was trusted.
  options.inflate_floor_bytes = std::uint64_t{16} << 20;
  options.max_inflate_ratio = 0;  // the floor alone: 16 MB whatever the input size
  try {
    const Mesh mesh = read_mesh_from_memory(bytes, format, "fuzz", nullptr, options);
    // A mesh that was accepted must be consistent: every face index names a vertex.
    for (Eigen::Index i = 0; i < mesh.F.size(); ++i) {
      const Index v = mesh.F.data()[i];
      if (v < 0 || v >= mesh.num_vertices()) std::abort();
    }
  } catch (const IoError& e) {
    const std::string_view what = e.what();
    if (what.substr(0, 6) != "fuzz: " || what.find('\n') != std::string_view::npos) std::abort();
  }
  return 0;
}

}  // namespace vertexflow::fuzz
