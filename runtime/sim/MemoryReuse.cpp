// The heap prefaulter (MemoryReuse.h): a thread that faults in the heap's pages just ahead of the
// thread writing them.
#include "sim/MemoryReuse.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

#if defined(__linux__) && defined(__GLIBC__)
#include <malloc.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <unistd.h>
#if defined(MADV_POPULATE_WRITE)
#define QDOT_HEAP_PREFAULT 1
#endif
#endif

namespace qdot::rt {
namespace {

#ifdef QDOT_HEAP_PREFAULT
// The heap (from its top when the thread starts) is cut into 2 MiB windows. A window whose first
// page the process has touched (resident, and not populated here) is being written: it and the
// kLead windows after it are populated at once (MADV_POPULATE_WRITE faults pages in as a write
// would, without changing a byte), so a sequential writer — a growing vector, the symbolic arena, a
// table being cleared, IDA's vectors — meets pages already there, and the kernel's zeroing runs on
// this thread instead. Windows nobody touches (capacity reserved and never used: 0.7 GB of the 10⁶
// chain's heap) stay unpopulated, so the resident memory stays what the process uses plus at most
// kLead windows per block being written. Populating everything the heap grows by instead raised the
// 10⁶ chain's peak from 1.58 to 2.29 GB. The lead is a sixteenth of the heap, at most 32 MiB, so
// that the prefaulter stays ahead of a writer that fills memory at full speed (a table cleared by
// fill_n): with 8 MiB the compile's own thread still zeroed huge pages itself (perf:
// clear_page_erms), at 64 MiB nothing more is gained; the price is 26 MB of peak at 10⁶ masses
// (1.58 → 1.61 GB).
// Until the heap has grown by 64 MiB nothing is populated: a small model's process touches a few
// MB, and what it would gain is less than what a populated lead it never uses costs.
class HeapPrefaulter {
 public:
  void start() {
    if (thread_.joinable()) return;
    stop_ = false;
    // From now: what the caller allocates next is above it. Rounded up, as mincore fails on a range
    // with unmapped pages (the heap starts at a page, not a window).
    uintptr_t base = (heapTop() + kWindow - 1) & ~(kWindow - 1);
    thread_ = std::thread([this, base] { run(base); });
  }
  void stop() {
    if (!thread_.joinable()) return;
    {
      std::lock_guard lock(mutex_);
      stop_ = true;
    }
    wake_.notify_one();
    thread_.join();
  }
  ~HeapPrefaulter() { stop(); }
  size_t populatedBytes() const { return populatedBytes_.load(std::memory_order_relaxed); }

 private:
  static constexpr uintptr_t kWindow = uintptr_t{2} << 20;
  static constexpr size_t kLead = 16;  ///< windows populated after a touched one, at most (a sixteenth of the heap)
  static constexpr uintptr_t kStartFrom = uintptr_t{64} << 20;  ///< heap grown by less: nothing populated
  static constexpr uintptr_t kPadFrom = uintptr_t{256} << 20;
  static constexpr uintptr_t kTopPad = uintptr_t{64} << 20;

  // sbrk(0) only reads the current break.
  static uintptr_t heapTop() { return reinterpret_cast<uintptr_t>(sbrk(0)); }

  // Page faults taken so far by the process's other threads (what this thread populates counts as
  // its own). Unchanged since the last look: nobody touched new memory, nothing to look for.
  static long othersFaults() {
    rusage all{}, own{};
    if (getrusage(RUSAGE_SELF, &all) != 0 || getrusage(RUSAGE_THREAD, &own) != 0) return -1;
    return all.ru_minflt - own.ru_minflt;
  }

  void run(uintptr_t base) {
    auto pause = std::chrono::microseconds(250);
    long seen = -2;
    std::unique_lock lock(mutex_);
    while (!stop_) {
      lock.unlock();
      bool populated = false;
      if (long faults = othersFaults(); faults != seen || faults < 0) {
        seen = faults;
        std::optional<bool> found = populateTouchedWindows(base);
        if (!found) return;
        populated = *found;
      }
      // Idle (a small model, or the solver running in memory already there): look less often.
      pause = populated ? std::chrono::microseconds(250) : std::min(2 * pause, std::chrono::microseconds(2000));
      lock.lock();
      wake_.wait_for(lock, pause, [this] { return stop_.load(); });
    }
  }

  // One look at the heap's residency (one mincore from the first window not done to the top):
  // populates every window touched since the last look and its lead. Whether it populated any;
  // nullopt where populating fails (before Linux 5.14, or where the heap shrank meanwhile: then the
  // process faults its pages in itself, as without this thread).
  std::optional<bool> populateTouchedWindows(uintptr_t base) {
    const uintptr_t page = static_cast<uintptr_t>(sysconf(_SC_PAGESIZE));
    uintptr_t top = heapTop() & ~(page - 1);
    if (top <= base || top - base < kStartFrom) return false;  // a small model: nothing worth a thread's work
    done_.resize((top - base + kWindow - 1) / kWindow, 0);
    // A large heap grows by large blocks (the symbolic arena's chunks, tables, vectors): let the
    // heap's top run ahead of them, so that the lead covers the next block before it is allocated.
    if (!topPadded_ && top - base >= kPadFrom) topPadded_ = mallopt(M_TOP_PAD, static_cast<int>(kTopPad)) == 1;
    const size_t lead = std::clamp<size_t>(done_.size() / 16, 1, kLead);
    size_t first = static_cast<size_t>(std::find(done_.begin(), done_.end(), 0) - done_.begin());
    uintptr_t from = base + first * kWindow;
    if (from >= top) return false;
    resident_.resize((top - from) / page);
    if (mincore(reinterpret_cast<void*>(from), top - from, resident_.data()) != 0) return false;
    bool populated = false;
    for (size_t w = first; w < done_.size() && !stop_; ++w) {
      uintptr_t begin = base + w * kWindow;
      if (begin >= top) break;
      if (done_[w] || !(resident_[(begin - from) / page] & 1)) continue;
      size_t last = std::min(done_.size(), w + 1 + lead);
      uintptr_t end = std::min(top, base + last * kWindow);
      if (madvise(reinterpret_cast<void*>(begin), end - begin, MADV_POPULATE_WRITE) != 0) return std::nullopt;
      populatedBytes_.fetch_add(end - begin, std::memory_order_relaxed);
      std::fill(done_.begin() + static_cast<long>(w), done_.begin() + static_cast<long>(last), 1);
      w = last - 1;
      populated = true;
    }
    return populated;
  }

  std::atomic<size_t> populatedBytes_{0};
  bool topPadded_ = false;
  std::vector<char> done_;                ///< per window: populated here, or found touched
  std::vector<unsigned char> resident_;  ///< mincore's answer, per page from the first window not done
  std::thread thread_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::atomic<bool> stop_ = false;  ///< set under mutex_ (for the wait), read without it while populating
};

HeapPrefaulter& prefaulter() {
  static HeapPrefaulter p;
  return p;
}
#endif

}  // namespace

void startHeapPrefault() {
#ifdef QDOT_HEAP_PREFAULT
  prefaulter().start();
#endif
}

void stopHeapPrefault() {
#ifdef QDOT_HEAP_PREFAULT
  prefaulter().stop();
#endif
}

size_t heapPrefaultedBytes() {
#ifdef QDOT_HEAP_PREFAULT
  return prefaulter().populatedBytes();
#else
  return 0;
#endif
}

}  // namespace qdot::rt
