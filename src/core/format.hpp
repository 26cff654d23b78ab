#pragma once
// Numbers in text outputs: the shortest decimal form that reads back to the same double.
#include <charconv>
#include <string>

namespace angiosynth {

inline std::string exactNumber(double v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

}  // namespace angiosynth
