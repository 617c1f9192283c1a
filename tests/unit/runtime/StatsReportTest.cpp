// --stats: the peak memory line says what the process used, in MiB, and is left out where the
// system gives no figure.
#include <gtest/gtest.h>

#include <chrono>
#include <optional>
#include <vector>

#include "sim/PeakMemory.h"
#include "sim/ProcessClock.h"
#include "sim/StatsReport.h"

namespace qdot::rt {
namespace {

TEST(StatsReport, PeakMemoryIsReportedInMebibytesWhenKnown) {
  SimulationResult r;
  r.peakMemoryBytes = 3 * 1048576 + 104858;  // 3.1 MiB
  EXPECT_NE(formatStats(r).find("  peak memory            3.1 MiB resident"), std::string::npos) << formatStats(r);
  EXPECT_EQ(formatStats(r).find("ahead of use"), std::string::npos) << "nothing prefaulted: not mentioned";
  r.prefaultedBytes = 96 * 1048576;
  EXPECT_NE(formatStats(r).find("3.1 MiB resident (the whole process so far); 96 MiB of heap populated ahead of use"),
            std::string::npos)
      << formatStats(r);
  r.peakMemoryBytes = 0;
  EXPECT_EQ(formatStats(r).find("peak memory"), std::string::npos);
}

// "file → first step" is the first step's instant counted from the process's start (the kernel's
// record of it, in ticks of 10 ms): an instant 50 ms later is 50 ms further, and this test's own
// process started less than a minute before it.
TEST(StatsReport, FirstStepIsTimedFromTheProcessStart) {
  SimulationResult r;
  EXPECT_EQ(formatStats(r).find("after the process started"), std::string::npos) << "no first step seen: not said";
#if defined(__linux__)
  auto now = std::chrono::steady_clock::now();
  std::optional<double> since = secondsSinceProcessStart(now);
  ASSERT_TRUE(since.has_value());
  EXPECT_GE(*since, 0.0);
  EXPECT_LT(*since, 60.0);
  std::optional<double> later = secondsSinceProcessStart(now + std::chrono::milliseconds(50));
  ASSERT_TRUE(later.has_value());
  EXPECT_NEAR(*later - *since, 0.05, 0.005);
  r.firstStepDone = now;
  EXPECT_NE(formatStats(r).find("(first step 0.000 s, done "), std::string::npos) << formatStats(r);
  EXPECT_NE(formatStats(r).find(" s after the process started)"), std::string::npos) << formatStats(r);
#endif
}

#if defined(__linux__)
TEST(StatsReport, PeakMemoryCountsWhatTheProcessTouched) {
  size_t before = peakResidentBytes();
  std::vector<char> block(size_t{256} << 20);  // touched: zero-filled by the vector
  for (size_t i = 0; i < block.size(); i += 4096) block[i] = static_cast<char>(i);
  size_t after = peakResidentBytes();
  EXPECT_GE(after, before);
  EXPECT_GE(after, block.size());
  EXPECT_LT(after, size_t{4} << 30);
}
#endif

}  // namespace
}  // namespace qdot::rt
