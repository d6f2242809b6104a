// The CLI's memory allocator. Built with jemalloc (VERTEXFLOW_JEMALLOC, the default when
// libjemalloc-dev is installed), the process allocates through it with transparent huge pages.
//
// Why: the flow's stages allocate and first touch arrays of tens to hundreds of bytes per vertex
// (topology, curvature, the system's factors, the solver's vectors), and at scan sizes the page
// faults of that first touch, 4 KiB at a time, were a quarter of the wall time: glibc's malloc
// maps every large block afresh and this machine's kernel gives huge pages only to memory that
// asks for them (transparent_hugepage=madvise). The same run with jemalloc asking for huge pages
// (docs/benchmarks.md, "The allocator"): arm1m 10.44 -> 8.48 s and a 9.7M-vertex mesh 215 ->
// 116 s (medians, alternating with the C library's malloc), the same output bytes, about the same
// peak RSS. The library itself does not choose an allocator; docs/benchmarks.md says how a
// program or Python gets the same.
#include "allocator.h"

#include <string>

#if defined(VERTEXFLOW_WITH_JEMALLOC)
#include <jemalloc/jemalloc.h>

// jemalloc reads its options from this symbol when it starts (before main); MALLOC_CONF in the
// environment still overrides them. thp:always advises huge pages on every mapping it makes;
// metadata_thp:auto its own bookkeeping once that is large. dirty_decay_ms:1000 returns freed
// pages after a second instead of ten: a phase still reuses its own, and what the previous phase
// freed is not held through the next one's peak; retain:false unmaps what it returns instead of
// keeping it for reuse (arm1m's peak 752 -> 734 MB at the same speed). Both measured against
// the defaults in docs/benchmarks.md, "The allocator".
extern "C" {
// NOLINTNEXTLINE: the name and type are jemalloc's interface.
const char* malloc_conf = "thp:always,metadata_thp:auto,dirty_decay_ms:1000,retain:false";
}
#endif

namespace vertexflow::cli {

std::string allocator_description() {
#if defined(VERTEXFLOW_WITH_JEMALLOC)
  const char* version = nullptr;
  const char* thp = nullptr;
  std::size_t size = sizeof(const char*);
  if (mallctl("version", static_cast<void*>(&version), &size, nullptr, 0) != 0 || version == nullptr)
    return "jemalloc (version unknown)";
  size = sizeof(const char*);
  const bool has_thp = mallctl("opt.thp", static_cast<void*>(&thp), &size, nullptr, 0) == 0 && thp != nullptr;
  return std::string("jemalloc ") + version + (has_thp ? std::string(", transparent huge pages: ") + thp : "");
#else
  return "the C library's malloc";
#endif
}

}  // namespace vertexflow::cli
