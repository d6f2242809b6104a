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

#include "page_pool.h"

#include <string>

#if defined(VERTEXFLOW_WITH_JEMALLOC)
#include <jemalloc/jemalloc.h>

// jemalloc reads its options from this symbol when it starts (before main); MALLOC_CONF in the
// environment still overrides them. thp:always advises huge pages on every mapping it makes;
// metadata_thp:auto its own bookkeeping once that is large; retain:false unmaps what it returns
// instead of keeping the address range (arm1m's peak 752 -> 734 MB at the same speed; docs/
// benchmarks.md, "The allocator"). What it returns goes to the page pool (page_pool.cpp), whose
// pages serve any request of any arena, so jemalloc keeps nothing itself: dirty_decay_ms:0
// returns freed extents at once (with a second's decay, as before the pool, they sat in the
// arena while other requests mapped fresh pages: a 619k-vertex mesh peaked at 439 MB against 414
// MB, at the same speed); narenas:1 puts every thread's requests in one arena that carries the
// pool's hooks; oversize_threshold:0 turns off the separate arena for requests of 8 MiB and
// more, which would keep jemalloc's own hooks (docs/benchmarks.md, "The page pool").
extern "C" {
// NOLINTNEXTLINE: the name and type are jemalloc's interface.
const char* malloc_conf = "thp:always,metadata_thp:auto,dirty_decay_ms:0,retain:false,narenas:1,oversize_threshold:0";
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
  return std::string("jemalloc ") + version + (has_thp ? std::string(", transparent huge pages: ") + thp : "") +
         (page_pool_installed() ? ", page pool" : "");
#else
  return "the C library's malloc";
#endif
}

}  // namespace vertexflow::cli
