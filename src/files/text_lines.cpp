#include "files/text_lines.hpp"

#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>

#include "core/error.hpp"

namespace angiosynth {

std::string trimmed(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r\n\f\v");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t\r\n\f\v") - b + 1);
}

std::vector<TextLine> readTextLines(const std::filesystem::path& file, const std::string& what) {
  std::error_code ec;
  if (std::filesystem::exists(file, ec) && !std::filesystem::is_regular_file(file, ec))
    throw InputError(file.string(), 0, what + " file is not a regular file (a directory or device); give a text file");
  std::ifstream in(file, std::ios::binary);
  if (!in) {
    const bool exists = std::filesystem::exists(file);
    throw InputError(file.string(), 0, std::string(exists ? "cannot read " : "no such ") + what + (exists ? " (permission?)" : " file"));
  }
  std::vector<TextLine> lines;
  std::string raw;
  int number = 0;
  while (std::getline(in, raw)) {
    ++number;
    if (const auto hash = raw.find('#'); hash != std::string::npos) raw.erase(hash);
    auto t = trimmed(raw);
    if (!t.empty()) lines.push_back({number, std::move(t)});
  }
  return lines;
}

std::vector<std::string> splitWords(const std::string& s) {
  std::istringstream in(s);
  std::vector<std::string> words;
  for (std::string w; in >> w;) words.push_back(w);
  return words;
}

double parseNumber(const std::string& word, const std::string& file, int line, const std::string& what) {
  double v = 0;
  const auto [ptr, ec] = std::from_chars(word.data(), word.data() + word.size(), v);
  if (ec != std::errc() || ptr != word.data() + word.size() || !std::isfinite(v))
    throw InputError(file, line, what + ": '" + word + "' is not a number");
  return v;
}

std::int64_t parseInteger(const std::string& word, const std::string& file, int line, const std::string& what) {
  std::int64_t v = 0;
  const char* b = word.data();
  if (!word.empty() && word[0] == '+') ++b;
  const auto [ptr, ec] = std::from_chars(b, word.data() + word.size(), v);
  if (ec != std::errc() || ptr != word.data() + word.size()) throw InputError(file, line, what + ": '" + word + "' is not a whole number");
  return v;
}

}  // namespace angiosynth
