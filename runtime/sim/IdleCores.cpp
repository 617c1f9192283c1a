// IdleCoreGauge: see IdleCores.h.
#include "sim/IdleCores.h"

#include <algorithm>
#include <cstdio>
#include <thread>

namespace qdot::rt {
namespace {

CpuTicks readCpuTicks() {
  CpuTicks t;
  std::FILE* f = std::fopen("/proc/stat", "r");
  if (!f) return t;
  unsigned long long v[8] = {};
  if (std::fscanf(f, "cpu %llu %llu %llu %llu %llu %llu %llu %llu", &v[0], &v[1], &v[2], &v[3], &v[4], &v[5], &v[6], &v[7]) == 8) {
    for (unsigned long long x : v) t.total += x;
    t.idle = v[3] + v[4];
  }
  std::fclose(f);
  return t;
}

// The fourth field of /proc/loadavg, "running/total": tasks runnable now, the reader among them.
int readRunnableTasks() {
  std::FILE* f = std::fopen("/proc/loadavg", "r");
  if (!f) return -1;
  double load1 = 0, load5 = 0, load15 = 0;
  int running = -1, total = 0;
  if (std::fscanf(f, "%lf %lf %lf %d/%d", &load1, &load5, &load15, &running, &total) != 5) running = -1;
  std::fclose(f);
  return running;
}

}  // namespace

MachineReading readMachine() { return {readCpuTicks(), readRunnableTasks()}; }

IdleCoreGauge::IdleCoreGauge(unsigned cores)
    : cores_(static_cast<int>(std::max(1u, cores > 0 ? cores : std::thread::hardware_concurrency()))),
      idleAtInstants_(static_cast<size_t>(cores_) + 1, 0) {}

void IdleCoreGauge::add(const MachineReading& r) {
  if (r.ticks.total > 0) {
    if (!hasTicks_) first_ = r.ticks;
    last_ = r.ticks;
    hasTicks_ = true;
  }
  if (r.runnable >= 1) {
    ++idleAtInstants_[std::clamp(cores_ - r.runnable, 0, cores_)];
    ++instants_;
  }
}

double IdleCoreGauge::idleCores() const {
  if (fromTicks())
    return double(cores_) * double(last_.idle - first_.idle) / double(last_.total - first_.total);
  if (instants_ < 2) return -1;
  // The lower median: a kernel thread runnable for a moment (rcu, a kworker) at one instant does
  // not make a busy core, another job running through most of them does.
  int below = 0;
  for (int idle = 0; idle <= cores_; ++idle) {
    below += idleAtInstants_[idle];
    if (2 * below >= instants_) return idle;
  }
  return cores_;
}

}  // namespace qdot::rt
