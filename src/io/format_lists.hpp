#pragma once
// What every format registry (volume, graph, mesh) answers from its table of entries with a
// `name` and a `meaning`: the entry of a name, the names, and "name (meaning), …" for help.
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace angiosynth {

template <class Format>
const Format* findFormat(std::span<const Format> formats, std::string_view name) {
  for (const auto& f : formats)
    if (f.name == name) return &f;
  return nullptr;
}

template <class Format>
std::vector<std::string> formatNames(std::span<const Format> formats) {
  std::vector<std::string> names;
  for (const auto& f : formats) names.emplace_back(f.name);
  return names;
}

template <class Format>
std::string formatSummary(std::span<const Format> formats) {
  std::string s;
  for (const auto& f : formats) s += (s.empty() ? "" : ", ") + std::string(f.name) + " (" + std::string(f.meaning) + ")";
  return s;
}

}  // namespace angiosynth
