// What first touching memory costs on this machine, and how it depends on how long the memory
// lay free before (docs/benchmarks.md, "Fresh pages on this VM"). Maps SIZE GiB (huge pages
// advised, as the CLI's allocator does), touches a byte per 4 KiB page, unmaps, waits SECONDS,
// and repeats three times; prints the touch rate of each round.
//
//   build/bin/page_fault_cost 2 0    # memory freed a moment ago
//   build/bin/page_fault_cost 2 6    # memory that lay free for 6 s
//
// On a VM whose kernel reports free pages to the host (virtio-balloon free page reporting, here
// page_reporting.page_reporting_order=11 on the kernel command line), the host takes such pages
// back after about two seconds, and touching them again costs a fault in the host too.
#include <sys/mman.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: page_fault_cost SIZE_GIB WAIT_SECONDS\n");
    return 2;
  }
  const auto bytes = static_cast<std::size_t>(std::atof(argv[1]) * (1u << 30));
  const int wait = std::atoi(argv[2]);
  for (int round = 0; round < 3; ++round) {
    void* mapped = mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (mapped == MAP_FAILED) {
      std::perror("page_fault_cost: mmap");
      return 1;
    }
    madvise(mapped, bytes, MADV_HUGEPAGE);
    auto* p = static_cast<volatile char*>(mapped);
    const auto start = std::chrono::steady_clock::now();
    for (std::size_t i = 0; i < bytes; i += 4096) p[i] = 1;
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::printf("round %d: touched %.2f GB in %.3f s, %.2f GB/s\n", round, static_cast<double>(bytes) / 1e9, seconds,
                static_cast<double>(bytes) / 1e9 / seconds);
    std::fflush(stdout);
    munmap(mapped, bytes);
    sleep(static_cast<unsigned>(wait));
  }
  return 0;
}
