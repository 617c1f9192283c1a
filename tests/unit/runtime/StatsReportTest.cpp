// --stats: the peak memory line says what the process used, in MiB, and is left out where the
// system gives no figure.
#include <gtest/gtest.h>

#include <vector>

#include "sim/PeakMemory.h"
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
