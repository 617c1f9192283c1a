// How a qdot process treats the memory it frees before the solve (issue 15).
//
// A large model's compile frees most of what it allocated (each stage's input once the next has
// what it needs, driver::CompileOptions::releaseStages), and the integrator's setup and first step
// then allocate hundreds of MB (IDA's vectors, KLU's matrix and factors). glibc serves blocks of
// 128 KiB–32 MiB and more by mmap and gives them back on free, so every one of those pages was
// faulted in, zeroed by the kernel and unmapped, only for the solver to fault in new ones: on this
// project's machines first touching memory costs 0.5–1.8 s per GiB, a third to a half of the
// 10⁶-mass chain's time to its first step (bench/README.md, "Freed memory reused").
//
// reuseFreedMemory() (at the start of `qdot` and of the executables it builds) makes every block
// come from the heap and keeps freed pages there, so later stages and the solver reuse pages that
// are already mapped; returnFreedMemory() (after the solver's first steps, runtime/sim/Simulation.cpp)
// gives back what is still free, so a long run does not hold the compiler's leftovers.
//
// What the process does allocate afresh is still faulted in page by page (a third of the 10⁶
// chain's compile): so reuseFreedMemory() also starts the heap prefaulter, a thread that faults in
// the pages just ahead of where the process writes into new heap (MemoryReuse.cpp says how it
// finds them), on the core that the single-threaded compile leaves idle; returnFreedMemory() stops
// it. At 10⁶ masses that takes the compile from 2.3 to 1.5 s and the file → first step from 3.6
// to 2.6 s for 2.5 % more peak memory (bench/README.md, "Heap prefaulted").
//
// The process's other threads (the KLU plan made ahead, ida/IdaSession.cpp; the JIT) take their
// blocks from the same heap (one malloc arena): a thread's own arena is memory mapped afresh and
// never prefaulted, so at 10⁶ masses the KLU plan spent half its 0.2 s faulting in new pages while
// the solver's setup waited for it (0.09 s with one arena). The threads allocate little at the same
// time: a lock shared among them costs nothing measurable (bench/tiering_bench.py).
//
// Only the time to fault pages changes; every result is the same to the bit.
#pragma once

#include <climits>
#include <cstddef>
#include <cstdlib>
#include <string_view>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace qdot::rt {

/// Starts the heap prefaulter (above), if the system has MADV_POPULATE_WRITE (Linux 5.14); again: no effect.
void startHeapPrefault();
/// Stops it (waits for its thread); not started: no effect.
void stopHeapPrefault();
/// The bytes of heap it has populated so far (windows ahead of the writer; `--stats` shows them).
size_t heapPrefaultedBytes();

/// Blocks of any size from the heap, and no trimming of freed pages until returnFreedMemory().
/// Call once, before the process allocates much. (Where glibc cannot map more heap it still maps
/// blocks one by one, so this cannot make an allocation fail.) QDOT_REUSE_FREED_MEMORY=0 in the
/// environment leaves glibc's defaults, for measuring the difference (bench/scaling_bench.py);
/// QDOT_PREFAULT_HEAP=0 reuses freed memory without the prefaulter.
inline void reuseFreedMemory() {
#if defined(__GLIBC__)
  if (const char* v = std::getenv("QDOT_REUSE_FREED_MEMORY"); v && std::string_view(v) == "0") return;
  mallopt(M_MMAP_MAX, 0);
  mallopt(M_ARENA_MAX, 1);  // the other threads' blocks from this heap too (above)
  mallopt(M_TRIM_THRESHOLD, INT_MAX);  // free() trims the heap's top only beyond this (the largest value)
  if (const char* v = std::getenv("QDOT_PREFAULT_HEAP"); !v || std::string_view(v) != "0") startHeapPrefault();
#endif
}

/// Stops the prefaulter and gives the pages of freed blocks back to the system.
inline void returnFreedMemory() {
#if defined(__GLIBC__)
  stopHeapPrefault();
  malloc_trim(0);
#endif
}

}  // namespace qdot::rt
