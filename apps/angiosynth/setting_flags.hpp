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
        } catch (const std::exception&) { return "'" + text + "' is not a number"; }
        if (!std::isfinite(v) || !s.range.holds(v)) return show(v) + " is out of range; allowed: " + s.range.text() + rangeUnit(s);
        return s.problem ? s.problem(v) : std::string();
      },
      s.range.text());
}

// Each flag with the setting it fills.
template <class Options>
using SettingFlagList = std::vector<std::pair<const Setting<Options>*, const CLI::Option*>>;

template <class Options>
SettingFlagList<Options> addSettingFlags(CLI::App& c, const std::vector<Setting<Options>>& settings, Options& o) {
  SettingFlagList<Options> added;
  for (const auto& s : settings) {
    if (!s.flag) continue;
    const std::string key = std::string("[") + s.table + "] " + s.key;
    const std::string help =
        s.flag[0] == '!' ? "sets " + key + " = false (" + s.meaning + ")" : std::string(s.meaning) + " (" + key + "; default " + s.fallback + ")";
    const std::size_t before = c.get_options().size();
    std::visit(
        [&](auto member) {
          if constexpr (detail::isChoiceField<decltype(member)>) {
            c.add_option_function<std::string>(
                 s.flag, [&o, member](const std::string& v) { member.set(o, v); }, help)
                ->check(CLI::IsMember(s.choices));
          } else {
            using T = std::remove_reference_t<decltype(o.*member)>;
            if constexpr (std::is_same_v<T, bool>) {
              if (s.flag[0] == '!')
                c.add_flag_callback(
                    s.flag + 1, [&o, member] { o.*member = false; }, help);
              else
                c.add_flag(s.flag, o.*member, help);
            } else if constexpr (std::is_same_v<T, std::optional<bool>>) {
              c.add_option_function<int>(
                   s.flag, [&o, member](const int& v) { o.*member = v != 0; }, help + "; 1 or 0")
                  ->check(CLI::IsMember({0, 1}));
            } else if constexpr (std::is_same_v<T, int>) {
              c.add_option(s.flag, o.*member, help)->check(CLI::Range(int(s.range.lo), int(s.range.hi)));
            } else if constexpr (std::is_same_v<T, std::int64_t>) {
              c.add_option(s.flag, o.*member, help)->check(CLI::Range(std::int64_t(s.range.lo), std::int64_t(s.range.hi)));
            } else if constexpr (std::is_same_v<T, std::optional<int>>) {
              c.add_option_function<int>(
                   s.flag, [&o, member](const int& v) { o.*member = v; }, help)
                  ->check(CLI::Range(int(s.range.lo), int(s.range.hi)));
            } else if constexpr (std::is_same_v<T, double> || std::is_same_v<T, std::optional<double>>) {
              c.add_option_function<double>(
                   s.flag, [&o, member](const double& v) { o.*member = v; }, help)
                  ->check(settingNumberCheck(s));
            } else if constexpr (std::is_same_v<T, std::string>) {
              c.add_option(s.flag, o.*member, help)->check(CLI::IsMember(s.choices));
            } else if constexpr (std::is_same_v<T, std::vector<double>>) {
              c.add_option(s.flag, o.*member, help + " (" + std::to_string(s.count) + " numbers, comma-separated)")
                  ->delimiter(',')
                  ->expected(int(s.count))
                  ->check(settingNumberCheck(s));
            } else if constexpr (std::is_same_v<T, std::optional<Vec3>>) {
              c.add_option_function<std::vector<double>>(
                   s.flag, [&o, member](const std::vector<double>& v) { o.*member = Vec3(v[0], v[1], v[2]); }, help + " (3 numbers, comma-separated)")
                  ->delimiter(',')
                  ->expected(3)
                  ->check(settingNumberCheck(s));
            } else {
              static_assert(std::is_same_v<T, std::vector<std::string>>);
              c.add_option(s.flag, o.*member, help + " (comma-separated)")->delimiter(',')->check(CLI::IsMember(s.choices));
            }
          }
        },
        s.field);
    added.emplace_back(&s, c.get_options()[before]);
  }
  return added;
}

// Flags that override a parameter file's settings: parsed into `values`, then copied onto the
// file's Options for each flag the command line held (applyTo).
template <class Options>
struct SettingOverrides {
  Options values;
  SettingFlagList<Options> flags;
  void add(CLI::App& c, const std::vector<Setting<Options>>& settings) {
    const auto more = addSettingFlags(c, settings, values);
    flags.insert(flags.end(), more.begin(), more.end());
  }
  void applyTo(Options& target) const {
    for (const auto& [s, option] : flags)
      if (option->count() > 0)
        std::visit(
            [&](auto member) {
              if constexpr (detail::isChoiceField<decltype(member)>)
                member.set(target, member.get(values));
              else
                target.*member = values.*member;
            },
            s->field);
  }
};

}  // namespace angiosynth::cli
