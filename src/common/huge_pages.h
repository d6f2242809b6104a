// Internal: transparent huge pages for large, freshly allocated buffers.
//
// A freshly allocated buffer of hundreds of megabytes is faulted in page by page on first
// write: with 4 KiB pages the kernel's fault handling was 17% of principal_curvatures' time at
// 1M vertices (bench_curvature). Advising 2 MiB pages before the first write cuts the faults
// 512-fold. Debian's default THP mode is "madvise", so nothing happens without the advice.
#pragma once

#include <cstddef>

namespace vertexflow {

/// Asks the kernel to back [data, data + bytes) with transparent huge pages. Call before the
/// buffer is first written. Only whole 2 MiB-aligned spans inside the range are affected; a
/// no-op for small buffers, on kernels without THP, and off Linux.
void advise_huge_pages(void* data, std::size_t bytes);

/// The same for an Eigen matrix or vector (any type with data() and size()).
template <class Dense>
void advise_huge_pages(Dense& matrix) {
  advise_huge_pages(static_cast<void*>(matrix.data()),
                    static_cast<std::size_t>(matrix.size()) * sizeof(*matrix.data()));
}

}  // namespace vertexflow
