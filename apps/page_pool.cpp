// The CLI's page pool (page_pool.h): jemalloc's extent hooks, so that the pages of memory the
// process frees stay with it and are moved (mremap) under its later allocations, of any size,
// instead of going back to the kernel and being faulted in afresh.
//
// Why: a 9.7M-vertex `enhance --report` faulted 38.5 GB of fresh pages for a 6 GB peak, and on
// this project's VM (docs/benchmarks.md, "Fresh pages on this VM" and "The page pool") a fresh
// huge page of memory the kernel had already returned to the host costs 0.3-0.5 GB/s of system
// time per thread: 35-41 s of a 114-126 s run. jemalloc alone cannot keep the pages without
// raising the peak: kept in its arenas (no purging at all) they were not reusable across size
// classes and arenas, and the peak rose from 6.0 to 8.1-8.4 GB. Moving pages by mremap makes any
// freed huge page serve any later request, so the resident set stays at the largest the live
// data needed. No maintained allocator offers this (jemalloc's own retained memory keeps
// address ranges, not pages), hence these hooks.
//
// Three rules keep the resident set at that of live data:
// - a request is filled with pooled pages only up to its size class's smallest request (jemalloc
//   rounds large requests up by up to a quarter, and a fresh tail nobody touches costs nothing,
//   whereas a moved page is resident);
// - for every fresh byte mapped while the pool holds pages, a pooled byte is given back (the
//   debt), since fresh pages the caller touches add to the resident set beside the pool's;
// - a mapping of less than a huge page goes back to the kernel, as before.
#include "page_pool.h"

#if defined(VERTEXFLOW_WITH_JEMALLOC) && defined(__linux__)
#include <jemalloc/jemalloc.h>
#include <sys/mman.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cerrno>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <string>

namespace vertexflow::cli {
namespace {

constexpr std::uintptr_t kHugePage = std::uintptr_t{2} << 20;

std::uintptr_t align_up(std::uintptr_t x, std::uintptr_t a) {
  return (x + a - 1) & ~(a - 1);
}
std::uintptr_t align_down(std::uintptr_t x, std::uintptr_t a) {
  return x & ~(a - 1);
}

// Ranges of whole 2 MiB-aligned huge pages that jemalloc gave back, still mapped and (mostly)
// resident. A fixed array: the hooks must not allocate. Entries are taken last in, first out.
struct Pool {
  struct Range {
    std::uintptr_t begin = 0;
    std::size_t bytes = 0;
  };
  static constexpr std::size_t kCapacity = 8192;
  std::mutex mutex;
  std::array<Range, kCapacity> ranges{};
  std::size_t count = 0;
  std::size_t pooled_bytes = 0;
  // Counters for VERTEXFLOW_PAGE_POOL_STATS.
  std::size_t reused_bytes = 0, fresh_bytes = 0, moves = 0;
  std::size_t debt = 0;  // fresh bytes mapped since the pool last gave pages back

  // Removes at most `most` bytes (a multiple of kHugePage) from the top range and returns them.
  // The caller holds the mutex and count > 0.
  Range take(std::size_t most) {
    Range& top = ranges[count - 1];
    const Range taken{top.begin, std::min(most, top.bytes)};
    top.begin += taken.bytes;
    top.bytes -= taken.bytes;
    pooled_bytes -= taken.bytes;
    if (top.bytes == 0) --count;
    return taken;
  }
};

Pool& pool() {
  static Pool p;
  return p;
}

void unmap(std::uintptr_t begin, std::size_t bytes) {
  if (bytes > 0) ::munmap(reinterpret_cast<void*>(begin), bytes);
}

// Moves `bytes` (a multiple of kHugePage) of pooled pages to `to`, replacing what is mapped
// there. A pooled range may span several mappings (it was assembled from moved pieces), and
// one mremap moves within one mapping only, so a failed move is retried a huge page at a time.
bool move_pages(std::uintptr_t from, std::size_t bytes, std::uintptr_t to, std::size_t& moves) {
  ++moves;
  if (::mremap(reinterpret_cast<void*>(from), bytes, bytes, MREMAP_MAYMOVE | MREMAP_FIXED,
               reinterpret_cast<void*>(to)) != MAP_FAILED)
    return true;
  for (std::size_t done = 0; done < bytes; done += kHugePage) {
    ++moves;
    if (::mremap(reinterpret_cast<void*>(from + done), kHugePage, kHugePage, MREMAP_MAYMOVE | MREMAP_FIXED,
                 reinterpret_cast<void*>(to + done)) == MAP_FAILED) {
      unmap(from + done, bytes - done);  // what could not move is given back; `to` stays fresh
      return false;
    }
  }
  return true;
}

// A fresh anonymous mapping of `bytes` at a multiple of `alignment`, huge pages advised.
std::uintptr_t map_fresh(std::size_t bytes, std::size_t alignment) {
  const std::size_t slack = alignment > 4096 ? alignment - 4096 : 0;
  void* p = ::mmap(nullptr, bytes + slack, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS | MAP_NORESERVE, -1, 0);
  if (p == MAP_FAILED) return 0;
  const auto raw = reinterpret_cast<std::uintptr_t>(p);
  const std::uintptr_t begin = align_up(raw, alignment);
  unmap(raw, begin - raw);
  unmap(begin + bytes, raw + bytes + slack - (begin + bytes));
  (void)::madvise(reinterpret_cast<void*>(begin), bytes, MADV_HUGEPAGE);
  return begin;
}

// Gives back pooled pages for the fresh bytes just mapped (Pool::debt), a huge page at a time:
// fresh pages the caller touches add to the resident set, and the pool must not hold pages
// beside them that live data no longer needs.
void repay(Pool& p, std::size_t fresh) {
  if (p.count == 0) {
    p.debt = 0;
    return;
  }
  p.debt += fresh;
  while (p.debt >= kHugePage && p.count > 0) {
    const Pool::Range given = p.take(align_down(p.debt, kHugePage));
    unmap(given.begin, given.bytes);
    p.debt -= given.bytes;
  }
  if (p.count == 0) p.debt = 0;
}

void* pool_alloc(extent_hooks_t*, void* new_addr, std::size_t size, std::size_t alignment, bool* zero, bool* commit,
                 unsigned) {
  if (new_addr != nullptr) return nullptr;  // no growing in place: jemalloc maps elsewhere
  Pool& p = pool();
  const std::size_t align =
      std::max<std::size_t>(size >= kHugePage ? std::max<std::size_t>(alignment, kHugePage) : alignment, 4096);
  std::uintptr_t begin = map_fresh(size, align);
  if (begin == 0) {
    // Out of address space (ulimit -v): the pooled ranges go back, then one more try.
    std::lock_guard<std::mutex> lock(p.mutex);
    while (p.count > 0) {
      const Pool::Range given = p.take(p.ranges[p.count - 1].bytes);
      unmap(given.begin, given.bytes);
    }
    p.debt = 0;
    begin = map_fresh(size, align);
    if (begin == 0) return nullptr;
  }
  *commit = true;
  // jemalloc rounds a large request up to its size class, 4 classes per doubling, and a fresh
  // mapping's untouched tail costs no memory, whereas pooled pages are resident. So only the
  // part every request of this class asks for is filled: the size less the class spacing.
  const std::size_t spacing = std::size_t{1} << (std::bit_width(size - 1) - 3);
  std::size_t need = *zero || size < kHugePage ? 0 : align_down(size - std::min(size, spacing), kHugePage);
  std::uintptr_t to = begin;
  std::lock_guard<std::mutex> lock(p.mutex);
  while (need > 0 && p.count > 0) {
    const Pool::Range moved = p.take(need);
    if (move_pages(moved.begin, moved.bytes, to, p.moves)) p.reused_bytes += moved.bytes;
    to += moved.bytes;
    need -= moved.bytes;
  }
  const std::size_t fresh = size - (to - begin);
  p.fresh_bytes += fresh;
  repay(p, fresh);
  *zero = to == begin;  // moved pages hold what they held
  return reinterpret_cast<void*>(begin);
}

bool pool_dalloc(extent_hooks_t*, void* addr, std::size_t size, bool, unsigned) {
  const auto begin = reinterpret_cast<std::uintptr_t>(addr);
  const std::uintptr_t first = align_up(begin, kHugePage), last = align_down(begin + size, kHugePage);
  if (last <= first) {
    unmap(begin, size);
    return false;
  }
  unmap(begin, first - begin);
  unmap(last, begin + size - last);
  Pool& p = pool();
  std::lock_guard<std::mutex> lock(p.mutex);
  if (p.count == Pool::kCapacity) {
    unmap(first, last - first);
    return false;
  }
  p.ranges[p.count++] = {first, last - first};
  p.pooled_bytes += last - first;
  return false;
}

void pool_destroy(extent_hooks_t*, void* addr, std::size_t size, bool, unsigned) {
  unmap(reinterpret_cast<std::uintptr_t>(addr), size);
}

bool pool_commit(extent_hooks_t*, void*, std::size_t, std::size_t, std::size_t, unsigned) {
  return false;  // mappings are always committed (Linux overcommits)
}

bool pool_decommit(extent_hooks_t*, void*, std::size_t, std::size_t, std::size_t, unsigned) {
  return true;  // not supported: jemalloc purges instead
}

bool pool_purge_forced(extent_hooks_t*, void* addr, std::size_t, std::size_t offset, std::size_t length, unsigned) {
  return ::madvise(static_cast<char*>(addr) + offset, length, MADV_DONTNEED) != 0;
}

bool pool_split(extent_hooks_t*, void*, std::size_t, std::size_t, std::size_t, bool, unsigned) {
  return false;
}

bool pool_merge(extent_hooks_t*, void*, std::size_t, void*, std::size_t, bool, unsigned) {
  return false;
}

extent_hooks_t hooks = {pool_alloc,
                        pool_dalloc,
                        pool_destroy,
                        pool_commit,
                        pool_decommit,
                        /*purge_lazy*/ nullptr,
                        pool_purge_forced,
                        pool_split,
                        pool_merge};

bool installed = false;

}  // namespace

void install_page_pool() {
  // VERTEXFLOW_PAGE_POOL=0 runs without it, for comparisons (docs/benchmarks.md).
  if (const char* off = std::getenv("VERTEXFLOW_PAGE_POOL"); off != nullptr && std::strcmp(off, "0") == 0) return;
  unsigned narenas = 0;
  std::size_t size = sizeof(narenas);
  if (mallctl("opt.narenas", &narenas, &size, nullptr, 0) != 0) return;
  extent_hooks_t* h = &hooks;
  // Every automatic arena (one with the CLI's options; setting the hooks creates the others).
  // jemalloc's separate arena for huge requests would keep its own hooks, so allocator.cpp turns
  // it off (oversize_threshold:0).
  bool all = true;
  for (unsigned i = 0; i < narenas; ++i) {
    const std::string name = "arena." + std::to_string(i) + ".extent_hooks";
    all = mallctl(name.c_str(), nullptr, nullptr, &h, sizeof(h)) == 0 && all;
  }
  installed = all;
}

bool page_pool_installed() {
  return installed;
}

void print_page_pool_stats() {
  if (std::getenv("VERTEXFLOW_PAGE_POOL_STATS") == nullptr) return;
  Pool& p = pool();
  std::fprintf(stderr, "page pool: reused %.1f MB, fresh %.1f MB, pooled %.1f MB, %zu moves\n",
               static_cast<double>(p.reused_bytes) / 1e6, static_cast<double>(p.fresh_bytes) / 1e6,
               static_cast<double>(p.pooled_bytes) / 1e6, p.moves);
}

}  // namespace vertexflow::cli

#else

namespace vertexflow::cli {
void install_page_pool() {}
bool page_pool_installed() {
  return false;
}
void print_page_pool_stats() {}
}  // namespace vertexflow::cli

#endif
