// How qdot writes a number in text meant to be read back (printers, disassembly, messages): the
// shortest text that reads back as the same double (std::to_chars without a precision).
#pragma once

#include <charconv>
#include <string>

namespace qdot {

inline std::string shortestText(double v) {
  char buf[32];  // the longest shortest form of a double is 24 characters
  auto res = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, res.ptr);
}

}  // namespace qdot
