#pragma once
// The command-line flags of declared settings (src/settings/schema.hpp): each setting with a flag
// becomes one option of the subcommand, filling the same Options field as its key in a parameter
// file, checked against the same range and choices, its help the setting's meaning and default.
#include <CLI/CLI.hpp>

#include <cmath>
#include <string>
#include <type_traits>
#include <vector>

#include "settings/schema.hpp"

namespace angiosynth::cli {

template <class Options>
CLI::Validator settingNumberCheck(const Setting<Options>& s) {
  return CLI::Validator(
      [&s](std::string& text) -> std::string {
        double v = 0;
        try {
          std::size_t used = 0;
          v = std::stod(text, &used);
          if (used != text.size()) return "'" + text + "' is not a number";
        } catch (const std::exception&) {
          return "'" + text + "' is not a number";
        }
        if (!std::isfinite(v) || !s.range.holds(v)) return show(v) + " is out of range; allowed: " + s.range.text() + rangeUnit(s);
        return s.problem ? s.problem(v) : std::string();
      },
      s.range.text());
}

template <class Options>
void addSettingFlags(CLI::App& c, const std::vector<Setting<Options>>& settings, Options& o) {
  for (const auto& s : settings) {
    if (!s.flag) continue;
    const std::string help = std::string(s.meaning) + " (default " + s.fallback + ")";
    std::visit(
        [&](auto member) {
          using T = std::remove_reference_t<decltype(o.*member)>;
          if constexpr (std::is_same_v<T, bool>) {
            c.add_flag(s.flag, o.*member, help);
          } else if constexpr (std::is_same_v<T, std::optional<bool>>) {
            c.add_option_function<int>(s.flag, [&o, member](const int& v) { o.*member = v != 0; }, help + "; 1 or 0")
                ->check(CLI::IsMember({0, 1}));
          } else if constexpr (std::is_same_v<T, int>) {
            c.add_option(s.flag, o.*member, help)->check(CLI::Range(int(s.range.lo), int(s.range.hi)));
          } else if constexpr (std::is_same_v<T, double> || std::is_same_v<T, std::optional<double>>) {
            c.add_option_function<double>(s.flag, [&o, member](const double& v) { o.*member = v; }, help)->check(settingNumberCheck(s));
          } else if constexpr (std::is_same_v<T, std::string>) {
            c.add_option(s.flag, o.*member, help)->check(CLI::IsMember(s.choices));
          } else if constexpr (std::is_same_v<T, std::vector<double>>) {
            c.add_option(s.flag, o.*member, help + " (" + std::to_string(s.count) + " numbers, comma-separated)")
                ->delimiter(',')
                ->expected(int(s.count))
                ->check(settingNumberCheck(s));
          } else {
            static_assert(std::is_same_v<T, std::vector<std::string>>);
            c.add_option(s.flag, o.*member, help + " (comma-separated)")->delimiter(',')->check(CLI::IsMember(s.choices));
          }
        },
        s.field);
  }
}

}  // namespace angiosynth::cli
