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

// Numbers in messages: six significant digits, or `digits`.
inline std::string show(double v, int digits = 6) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.*g", digits, v);
  return buf;
}

// "1 tree", "3 trees".
inline std::string counted(long long n, const std::string& noun) { return std::to_string(n) + " " + noun + (n == 1 ? "" : "s"); }

}  // namespace angiosynth
