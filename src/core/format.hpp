#pragma once
// Numbers in text outputs: the shortest decimal form that reads back to the same double.
#include <charconv>
#include <cstdio>
#include <string>
#include <vector>

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

// A CSV field (RFC 4180): quoted only when it holds a comma, a quote or a line break.
inline std::string csvField(const std::string& s) {
  if (s.find_first_of(",\"\r\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + '"';
}

// The fields of one CSV line as csvField writes them (a quoted field may hold commas and doubled
// quotes; a trailing carriage return is dropped).
inline std::vector<std::string> csvFieldsOf(const std::string& line) {
  std::vector<std::string> out(1);
  bool quoted = false;
  for (std::size_t k = 0; k < line.size(); ++k) {
    const char c = line[k];
    if (quoted) {
      if (c == '"' && k + 1 < line.size() && line[k + 1] == '"')
        out.back() += '"', ++k;
      else if (c == '"')
        quoted = false;
      else
        out.back() += c;
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      out.emplace_back();
    } else if (c != '\r') {
      out.back() += c;
    }
  }
  return out;
}

// "1 tree", "3 trees".
inline std::string counted(long long n, const std::string& noun) { return std::to_string(n) + " " + noun + (n == 1 ? "" : "s"); }

}  // namespace angiosynth
