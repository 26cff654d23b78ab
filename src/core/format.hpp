#pragma once
// Numbers in text outputs: the shortest decimal form that reads back to the same double.
#include <charconv>
#include <cstdio>
#include <string>

namespace angiosynth {

inline std::string exactNumber(double v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

// Numbers in messages: six significant digits.
inline std::string show(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

}  // namespace angiosynth
