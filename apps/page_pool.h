// The CLI's page pool (page_pool.cpp says why and how).
#pragma once

namespace vertexflow::cli {

/// Installs the pool's extent hooks on every automatic jemalloc arena, first thing in main, unless
/// VERTEXFLOW_PAGE_POOL=0; a no-op without jemalloc (sanitizer builds, -DVERTEXFLOW_JEMALLOC=OFF).
void install_page_pool();

/// Whether install_page_pool installed the hooks on every arena.
bool page_pool_installed();

/// With VERTEXFLOW_PAGE_POOL_STATS set, one line on stderr at a successful exit: the bytes the
/// pool supplied, those mapped fresh, those it holds, and its mremap calls.
void print_page_pool_stats();

}  // namespace vertexflow::cli
