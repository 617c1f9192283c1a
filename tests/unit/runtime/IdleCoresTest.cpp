// IdleCoreGauge (sim/IdleCores.h): the idle cores since the first reading, from the median of the
// instants of runnable tasks until the CPU tick counters cover enough time, then from the ticks.
#include <gtest/gtest.h>

#include "sim/IdleCores.h"

namespace qdot::rt {
namespace {

MachineReading reading(uint64_t total, uint64_t idle, int runnable) { return {{total, idle}, runnable}; }

TEST(IdleCoreGauge, UnknownUntilTwoReadings) {
  IdleCoreGauge gauge(2);
  EXPECT_EQ(gauge.idleCores(), -1);
  gauge.add(reading(1000, 500, 1));
  EXPECT_EQ(gauge.idleCores(), -1);  // one instant says little
}

TEST(IdleCoreGauge, EarlyOnTheInstantsMedianAnswers) {
  // Two cores; the run's own thread alone runnable, then a kernel thread beside it for a moment:
  // one instant in three does not make the second core busy. The ticks moved by 3 only (30 ms of
  // one core): too few to tell.
  IdleCoreGauge gauge(2);
  gauge.add(reading(1000, 500, 1));
  gauge.add(reading(1002, 501, 2));
  EXPECT_EQ(gauge.idleCores(), 0);  // one instant each way: the lower one
  gauge.add(reading(1003, 501, 1));
  EXPECT_EQ(gauge.idleCores(), 1);
  // Another job running through most instants does.
  gauge.add(reading(1004, 501, 2));
  gauge.add(reading(1005, 501, 2));
  EXPECT_EQ(gauge.idleCores(), 0);
}

TEST(IdleCoreGauge, TheTicksAnswerOnceTheyCoverEnough) {
  // 10 ticks of which 3 idle on 2 cores: 0.6 of a core idle, whatever the instants said.
  IdleCoreGauge gauge(2);
  gauge.add(reading(1000, 500, 1));
  gauge.add(reading(1000 + IdleCoreGauge::kFewestTicks - 1, 500, 1));
  EXPECT_DOUBLE_EQ(gauge.idleCores(), 1.0);
  gauge.add(reading(1010, 503, 1));
  EXPECT_DOUBLE_EQ(gauge.idleCores(), 0.6);
}

TEST(IdleCoreGauge, AnInstantCountsAtMostEveryCoreIdleAndAtLeastNone) {
  IdleCoreGauge gauge(2);
  gauge.add(reading(0, 0, 9));  // a crowded machine (and unreadable ticks)
  gauge.add(reading(0, 0, 1));
  gauge.add(reading(0, 0, 1));
  EXPECT_EQ(gauge.idleCores(), 1);  // 0, 1, 1 idle
  IdleCoreGauge empty(4);
  empty.add(reading(0, 0, 1));  // only the reading thread runnable: 3 of 4 idle, not 4
  empty.add(reading(0, 0, 1));
  EXPECT_EQ(empty.idleCores(), 3);
  IdleCoreGauge unreadable(2);
  unreadable.add(reading(0, 0, -1));
  unreadable.add(reading(0, 0, -1));
  EXPECT_EQ(unreadable.idleCores(), -1);
}

TEST(IdleCoreGauge, ReadsThisMachine) {
  // On Linux both files exist: two readings give an answer between none and all cores idle.
  IdleCoreGauge gauge(4);
  gauge.read();
  gauge.read();
  double idle = gauge.idleCores();
  EXPECT_GE(idle, 0.0);
  EXPECT_LE(idle, 4.0);
}

}  // namespace
}  // namespace qdot::rt
