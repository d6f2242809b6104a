// Internal: vertices at one position, bitwise, as the STL reader (read_mesh.cpp), the glTF reader
// (io/gltf.cpp) and the enhance engine's cut-open seams (mesh/cut_seams.cpp) weld them.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>

namespace vertexflow {

/// The bits of three coordinates, -0 taken as +0 (both compare equal as numbers).
using PositionKey = std::array<std::uint64_t, 3>;

inline PositionKey position_key(const double* xyz) {
  PositionKey key{};
  for (std::size_t c = 0; c < 3; ++c) {
    const double x = xyz[c] + 0.0;  // -0 becomes +0
    std::memcpy(&key[c], &x, sizeof x);
  }
  return key;
}

struct PositionKeyHash {
  std::size_t operator()(const PositionKey& p) const {
    std::uint64_t h = 0x9e3779b97f4a7c15ull;
    for (const auto x : p) h = (h ^ x) * 0xff51afd7ed558ccdull ^ (h >> 29);
    return static_cast<std::size_t>(h);
  }
};

}  // namespace vertexflow
