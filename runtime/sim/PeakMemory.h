// peakResidentBytes: the process's peak resident set so far (getrusage's ru_maxrss, which Linux
// gives in KiB), for `--stats`; 0 where the system has no such figure.
#pragma once

#include <cstddef>

#if defined(__unix__) || defined(__APPLE__)
#include <sys/resource.h>
#endif

namespace qdot::rt {

inline size_t peakResidentBytes() {
#if defined(__linux__)
  rusage usage{};
  return getrusage(RUSAGE_SELF, &usage) == 0 ? static_cast<size_t>(usage.ru_maxrss) * 1024 : 0;
#else
  return 0;
#endif
}

}  // namespace qdot::rt
