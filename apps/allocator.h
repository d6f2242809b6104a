// The CLI's memory allocator (allocator.cpp says which and why).
#pragma once

#include <string>

namespace vertexflow::cli {

/// "jemalloc 5.3.0-0-g..., transparent huge pages: always", or "the C library's malloc" when the
/// CLI was built without jemalloc. `vertexflow --version` prints it.
std::string allocator_description();

}  // namespace vertexflow::cli
