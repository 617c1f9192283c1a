// secondsSinceProcessStart: how long after the process started a steady-clock instant was, for
// `--stats` ("file → first step" is measured from the process's start, which the process itself
// cannot time: its own clock starts in main, after the loader). The start is the kernel's record
// (/proc/self/stat, in clock ticks of 10 ms since boot), so the figure may be up to one tick long.
// nullopt where the system has no such record.
#pragma once

#include <chrono>
#include <optional>

#if defined(__linux__)
#include <time.h>
#include <unistd.h>

#include <fstream>
#include <iterator>
#include <cstdlib>
#include <sstream>
#include <string>
#endif

namespace qdot::rt {

inline std::optional<double> secondsSinceProcessStart(std::chrono::steady_clock::time_point when) {
#if defined(__linux__)
  std::ifstream file("/proc/self/stat");
  std::string stat((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  size_t afterName = stat.rfind(')');  // the command name (field 2) may hold spaces and parentheses
  if (afterName == std::string::npos) return std::nullopt;
  std::istringstream fields(stat.substr(afterName + 1));
  std::string field;
  for (int k = 3; k <= 22 && fields >> field; ++k) {}  // field 22: start time in ticks since boot
  long ticks = sysconf(_SC_CLK_TCK);
  timespec boot{};
  if (!fields || ticks <= 0 || clock_gettime(CLOCK_BOOTTIME, &boot) != 0) return std::nullopt;
  double start = std::strtod(field.c_str(), nullptr) / static_cast<double>(ticks);
  double bootNow = static_cast<double>(boot.tv_sec) + 1e-9 * static_cast<double>(boot.tv_nsec);
  double sinceWhen = std::chrono::duration<double>(std::chrono::steady_clock::now() - when).count();
  return bootNow - sinceWhen - start;
#else
  (void)when;
  return std::nullopt;
#endif
}

}  // namespace qdot::rt
