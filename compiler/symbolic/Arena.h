// Arena: the bump allocator that holds every node of a Context and the operand arrays the nodes'
// spans point into. Objects must be trivially destructible: nothing is freed one by one, all the
// memory goes with the Context. Chunks grow geometrically, so allocation is a pointer increment.
// Also adviseHugePages: big DAGs are walked at random (intern table, nodes), so on Linux their
// large buffers ask for transparent huge pages, which saves most TLB misses.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <type_traits>
#include <vector>

#ifdef __linux__
#include <sys/mman.h>
#endif

// Under AddressSanitizer, unused arena memory is poisoned and allocations are separated by
// redzones, so an overflow from one node's operands into the next is still reported.
#if defined(__SANITIZE_ADDRESS__)
#define QDOT_ARENA_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define QDOT_ARENA_ASAN 1
#endif
#endif
#ifdef QDOT_ARENA_ASAN
#include <sanitizer/asan_interface.h>
#endif

namespace qdot::sym {

/// Asks the OS to back the 2 MiB-aligned part of [p, p + bytes) with huge pages. Call it before the
/// memory is first touched; a hint only (no effect where unsupported).
inline void adviseHugePages(void* p, size_t bytes) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  constexpr uintptr_t kHuge = uintptr_t{2} << 20;
  uintptr_t begin = (reinterpret_cast<uintptr_t>(p) + kHuge - 1) & ~(kHuge - 1);
  uintptr_t end = (reinterpret_cast<uintptr_t>(p) + bytes) & ~(kHuge - 1);
  if (end > begin) madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
#else
  (void)p, (void)bytes;
#endif
}

/// Uninitialised storage for n objects of T that may use huge pages (see adviseHugePages).
template <class T>
std::unique_ptr<T[]> allocateLarge(size_t n) {
  auto p = std::make_unique_for_overwrite<T[]>(n);
  adviseHugePages(p.get(), n * sizeof(T));
  return p;
}

class Arena {
 public:
  /// Uninitialised storage for n objects of T, aligned for T, valid as long as the Arena.
  template <class T>
  T* allocate(size_t n) {
    static_assert(std::is_trivially_destructible_v<T>);
    return static_cast<T*>(allocateBytes(n * sizeof(T), alignof(T)));
  }
  /// Bytes obtained from the system so far.
  size_t bytesReserved() const { return reserved_; }

  /// Uninitialised storage of `size` bytes aligned to `align` (a power of two).
  void* allocateBytes(size_t size, size_t align) {
    size_t pad = (align - reinterpret_cast<uintptr_t>(next_) % align) % align;
    if (size + pad + kRedzone > static_cast<size_t>(end_ - next_)) {
      newChunk(size + align + kRedzone);
      pad = (align - reinterpret_cast<uintptr_t>(next_) % align) % align;
    }
    std::byte* p = next_ + pad;
    next_ += pad + size + kRedzone;
#ifdef QDOT_ARENA_ASAN
    ASAN_UNPOISON_MEMORY_REGION(p, size);
#endif
    return p;
  }

 private:
  void newChunk(size_t atLeast) {
    size_t size = std::max(atLeast, chunkSize_);
    chunkSize_ = std::min<size_t>(chunkSize_ * 2, size_t{8} << 20);
    chunks_.push_back(allocateLarge<std::byte>(size));
    next_ = chunks_.back().get();
    end_ = next_ + size;
    reserved_ += size;
#ifdef QDOT_ARENA_ASAN
    ASAN_POISON_MEMORY_REGION(next_, size);
#endif
  }

#ifdef QDOT_ARENA_ASAN
  static constexpr size_t kRedzone = 16;
#else
  static constexpr size_t kRedzone = 0;
#endif

  std::vector<std::unique_ptr<std::byte[]>> chunks_;
  std::byte* next_ = nullptr;
  std::byte* end_ = nullptr;
  size_t chunkSize_ = size_t{64} << 10;
  size_t reserved_ = 0;
};

}  // namespace qdot::sym
