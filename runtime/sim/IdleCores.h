// IdleCoreGauge: how many of the machine's cores a run has left idle so far, for the tiering
// policy (a compile on an idle core takes nothing from the solver).
// Two readings, because neither alone answers early and well: the kernel's CPU time counters
// (/proc/stat, in ticks of 10 ms of one core) are the truth over an interval but need tens of
// milliseconds before they say anything, while the number of runnable tasks (/proc/loadavg's
// "running/total") is exact but an instant, and sometimes catches a kernel thread runnable for a
// moment. So the gauge takes the median of the instants until the ticks cover enough time, then
// answers from the ticks. A run of 0.1 s on a fast machine is decided in
// its first 20 ms, long before the ticks could tell (benchmarks/car_axis.qd).
#pragma once

#include <cstdint>
#include <vector>

namespace qdot::rt {

/// The machine's CPU time so far in clock ticks: all of it and the idle part (idle + iowait).
struct CpuTicks {
  uint64_t total = 0, idle = 0;
};

/// One reading of the machine: its CPU ticks (both 0 if unreadable) and the tasks runnable at that
/// instant, the reading thread among them (-1 if unreadable).
struct MachineReading {
  CpuTicks ticks;
  int runnable = -1;
};

/// Reads /proc/stat's first line and /proc/loadavg (~10 µs).
MachineReading readMachine();

class IdleCoreGauge {
 public:
  /// `cores`: the machine's (0: std::thread::hardware_concurrency()).
  explicit IdleCoreGauge(unsigned cores = 0);

  /// Adds a reading; the first one is where the interval starts. The runnable tasks counted
  /// include the reading thread, which is the run's own.
  void add(const MachineReading& r);
  void read() { add(readMachine()); }

  /// Idle cores on average since the first reading: from the ticks once they cover
  /// kFewestTicks, else the (lower) median of the instants from two readings on, else -1 (unknown).
  double idleCores() const;
  /// Whether idleCores() answers from the tick counters (else from the instants, or not at all).
  bool fromTicks() const { return hasTicks_ && last_.total >= first_.total + kFewestTicks; }

  /// Ticks (summed over cores) from which the tick counters answer: 80 ms of one core.
  static constexpr uint64_t kFewestTicks = 8;

 private:
  int cores_;
  CpuTicks first_, last_;
  bool hasTicks_ = false;
  std::vector<int> idleAtInstants_;  ///< [idle cores at an instant]: how many instants
  int instants_ = 0;
};

}  // namespace qdot::rt
