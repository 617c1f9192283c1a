// The heap prefaulter (MemoryReuse.h): a thread that faults in the heap's pages just ahead of the
// thread writing them.
#include "sim/MemoryReuse.h"

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <thread>
#include <vector>

#if defined(__linux__) && defined(__GLIBC__)
#include <sys/mman.h>
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
// 10⁶ chain's peak from 1.58 to 2.29 GB. The lead is 32 MiB so that the prefaulter stays ahead of a
// writer that fills memory at full speed (a table cleared by fill_n): with 8 MiB the compile's own
// thread still zeroed huge pages itself (perf: clear_page_erms), at 64 MiB nothing more is gained;
// the price is 26 MB of peak at 10⁶ masses (1.58 → 1.61 GB).
class HeapPrefaulter {
 public:
  void start() {
    if (thread_.joinable()) return;
    stop_ = false;
    uintptr_t base = heapTop() & ~(kWindow - 1);  // now: what the caller allocates next is above it
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

 private:
  static constexpr uintptr_t kWindow = uintptr_t{2} << 20;
  static constexpr size_t kLead = 16;

  // sbrk(0) only reads the current break.
  static uintptr_t heapTop() { return reinterpret_cast<uintptr_t>(sbrk(0)); }

  void run(uintptr_t base) {
    const uintptr_t page = static_cast<uintptr_t>(sysconf(_SC_PAGESIZE));
    std::vector<char> done;  // per window: populated here, or found touched
    auto pause = std::chrono::microseconds(250);
    std::unique_lock lock(mutex_);
    while (!stop_) {
      lock.unlock();
      uintptr_t top = heapTop() & ~(page - 1);
      if (top > base) done.resize((top - base + kWindow - 1) / kWindow, 0);
      bool populated = false;
      for (size_t w = 0; w < done.size() && !stop_; ++w) {
        if (done[w]) continue;
        uintptr_t begin = base + w * kWindow;
        unsigned char resident = 0;
        if (begin >= top || mincore(reinterpret_cast<void*>(begin), page, &resident) != 0 || !(resident & 1)) continue;
        size_t last = std::min(done.size(), w + 1 + kLead);
        uintptr_t end = std::min(top, base + last * kWindow);
        // Fails where unsupported (before Linux 5.14) or where the heap shrank meanwhile: then the
        // process faults its pages in itself, as without this thread.
        if (madvise(reinterpret_cast<void*>(begin), end - begin, MADV_POPULATE_WRITE) != 0) return;
        std::fill(done.begin() + static_cast<long>(w), done.begin() + static_cast<long>(last), 1);
        w = last - 1;
        populated = true;
      }
      // Idle (a small model, or the solver running in memory already there): look less often.
      pause = populated ? std::chrono::microseconds(250) : std::min(2 * pause, std::chrono::microseconds(2000));
      lock.lock();
      wake_.wait_for(lock, pause, [this] { return stop_; });
    }
  }

  std::thread thread_;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stop_ = false;
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

}  // namespace qdot::rt
