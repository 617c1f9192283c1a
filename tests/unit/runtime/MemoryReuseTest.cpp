// The heap prefaulter (sim/MemoryReuse.h): heap that the process starts writing is faulted in ahead
// of the writer; heap nobody touches stays unpopulated (what keeps the peak memory the process's
// own); contents are not changed; stopping returns.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <thread>

#include "sim/MemoryReuse.h"

#if defined(__linux__) && defined(__GLIBC__)
#include <malloc.h>
#include <sys/mman.h>
#include <unistd.h>
#endif

namespace qdot::rt::test {
namespace {

#if defined(__linux__) && defined(__GLIBC__) && defined(MADV_POPULATE_WRITE)
const size_t kPage = static_cast<size_t>(sysconf(_SC_PAGESIZE));
constexpr size_t kMiB = size_t{1} << 20;

bool resident(const char* p) {
  unsigned char v = 0;
  auto page = reinterpret_cast<uintptr_t>(p) & ~(kPage - 1);
  return mincore(reinterpret_cast<void*>(page), kPage, &v) == 0 && (v & 1);
}

bool kernelPopulates() {
  void* p = mmap(nullptr, kPage, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  bool ok = p != MAP_FAILED && madvise(p, kPage, MADV_POPULATE_WRITE) == 0;
  if (p != MAP_FAILED) munmap(p, kPage);
  return ok;
}

// The first byte of the first 2 MiB window starting inside [p, p + size).
char* firstWindow(char* p) {
  auto a = (reinterpret_cast<uintptr_t>(p) + 2 * kMiB - 1) & ~(2 * kMiB - 1);
  return reinterpret_cast<char*>(a);
}

TEST(HeapPrefault, PopulatesAheadOfTheWriterAndNotWhatNobodyTouches) {
  if (!kernelPopulates()) GTEST_SKIP() << "the kernel has no MADV_POPULATE_WRITE (Linux < 5.14)";
  mallopt(M_MMAP_MAX, 0);  // every block from the heap, as reuseFreedMemory() makes it
  mallopt(M_TRIM_THRESHOLD, INT_MAX);
  startHeapPrefault();
  startHeapPrefault();  // again: no effect
  const size_t size = 64 * kMiB;
  auto* written = static_cast<char*>(std::malloc(size));
  auto* untouched = static_cast<char*>(std::malloc(size));
  ASSERT_TRUE(written && untouched);
  char* window = firstWindow(written);
  char* ahead = window + 6 * kMiB;  // in the windows after the one being written
  // The prefaulter watches the heap (brk); a system whose malloc placed these blocks elsewhere, or
  // had that memory in use before, cannot show what this test checks.
  auto* top = static_cast<char*>(sbrk(0));
  if (untouched + size > top || written + size > top || resident(ahead) || resident(firstWindow(untouched) + 32 * kMiB)) {
    stopHeapPrefault();
    std::free(untouched), std::free(written);
    mallopt(M_MMAP_MAX, 65536);
    GTEST_SKIP() << "the blocks are not fresh heap here";
  }
  // The writer goes through the windows before `ahead`, a page each. (Touching only the first was
  // flaky under load: malloc's own headers are writes too, and a look of the prefaulter between the
  // two mallocs — a smaller heap, a shorter lead — could populate the first windows without
  // reaching `ahead`, and then count the writer's window as done.)
  for (char* w = window; w < ahead; w += 2 * kMiB) std::memset(w, 0x5a, kPage);
  bool populated = false;
  for (int k = 0; k < 400 && !populated; ++k) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
    populated = resident(ahead);
  }
  EXPECT_TRUE(populated) << "the windows ahead of the writer were not faulted in within 2 s";
  EXPECT_FALSE(resident(firstWindow(untouched) + 32 * kMiB)) << "heap nobody wrote was populated";
  // Populating changes no byte: what was written stays, what was not reads as zero.
  EXPECT_EQ(window[kPage - 1], 0x5a);
  EXPECT_EQ(ahead[123], 0);
  stopHeapPrefault();
  stopHeapPrefault();  // again: no effect
  std::free(untouched);
  std::free(written);
  mallopt(M_MMAP_MAX, 65536);
}
#endif

}  // namespace
}  // namespace qdot::rt::test
