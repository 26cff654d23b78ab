#pragma once
// Settings declared once. Each declaration names a setting's table and key, its unit, its range
// or choices, its default as a user reads it, its meaning, the field of an Options struct it fills
// and the command-line flag that overrides it. From the one list come the parameter file's reader
// (readSettings), the flags (apps/angiosynth/setting_flags.hpp), `angiosynth params` and the
// parameter reference (referenceRows); the rules between settings are declared beside them and
// checked on the filled Options, whichever way it was filled (checkRules).
#include <algorithm>
#include <cmath>
#include <optional>
#include <set>
#include <string>
#include <variant>
#include <vector>

#include "core/units.hpp"
#include "core/vec3.hpp"
#include "settings/toml_reader.hpp"

namespace angiosynth {

// A choice kept as an enum (or a bool) in Options: the words are the setting's choices, `get` and
// `set` translate between a word and the field.
template <class Options>
struct ChoiceField {
  std::string (*get)(const Options&);
  void (*set)(Options&, const std::string&);
};

// The words of an enum (or a bool) numbered from 0, ending with nullptr: words[k] names enum
// value k; "" names a value no file chooses ("unset").
template <std::size_t N>
std::vector<std::string> wordList(const char* const (&words)[N]) {
  std::vector<std::string> out;
  for (std::size_t k = 0; k + 1 < N; ++k)
    if (*words[k]) out.emplace_back(words[k]);
  return out;
}

// The ChoiceField of enum (or bool) member `Member` whose values `Words` names in order.
template <class Options, auto Member, const char* const* Words>
ChoiceField<Options> enumChoice() {
  return {[](const Options& o) { return std::string(Words[static_cast<int>(o.*Member)]); },
          [](Options& o, const std::string& word) {
            using E = std::remove_reference_t<decltype(o.*Member)>;
            for (int k = 0; Words[k]; ++k)
              if (*Words[k] && word == Words[k]) o.*Member = static_cast<E>(k);
          }};
}

template <class Options>
using SettingField =
    std::variant<bool Options::*, int Options::*, std::int64_t Options::*, double Options::*, std::optional<double> Options::*,
                 std::optional<bool> Options::*, std::string Options::*, std::vector<double> Options::*, std::vector<std::string> Options::*,
                 std::optional<Vec3> Options::*, std::optional<int> Options::*, ChoiceField<Options>>;

// The internal unit of a quantity, as sidecars record it.
inline const char* internalUnit(Dimension d) {
  switch (d) {
    case Dimension::Length: return "mm";
    case Dimension::Flow: return "mm^3/s";
    case Dimension::Pressure: return "Pa";
    case Dimension::Viscosity: return "Pa*s";
  }
  return "";
}

// How a number is bounded: lo < v or lo <= v, and v < hi or v <= hi.
struct SettingRange {
  double lo = -1e300, hi = 1e300;
  bool lo_open = false, hi_open = false;
  bool holds(double v) const { return (lo_open ? v > lo : v >= lo) && (hi_open ? v < hi : v <= hi); }
  std::string text() const { return std::string(lo_open ? "(" : "[") + show(lo) + ", " + (hi >= 1e300 ? "inf" : show(hi)) + (hi_open ? ")" : "]"); }
};

template <class Options>
struct Setting;

// The unit after a range in a message: the declared one, the length's mm, else the setting's unit
// when it is one ("degrees"), nothing for descriptions such as "true/false".
template <class Options>
std::string rangeUnit(const Setting<Options>& s) {
  if (s.range_unit) return std::string(" ") + s.range_unit;
  const std::string u = s.quantity ? internalUnit(*s.quantity) : s.unit;
  return u.empty() || u.find_first_of("[/ ") != std::string::npos || u == "count" ? "" : " " + u;
}

// A setting that belongs to one choice of another: label_threshold to label_policy = "threshold".
struct SettingCondition {
  const char* key = nullptr;
  const char* value = nullptr;
};

template <class Options>
struct Setting {
  const char* table;     // "mesh"
  const char* key;       // "sliver_angle"
  const char* unit;      // "degrees", "mm", "true/false", "count", … (a quantity given as "<number> <unit>" when `quantity`)
  const char* fallback;  // the default as a user reads it; nullptr: the setting is required
  const char* meaning;
  SettingField<Options> field;
  SettingRange range{};                // numbers, counts and the entries of a list of numbers
  std::vector<std::string> choices{};  // texts and lists of texts: the allowed values (none: any text but the empty one)
  std::size_t count = 0;               // a list of numbers: exactly this many
  // A quantity (or a list of lengths): strings with their unit in a file, the internal unit (mm,
  // Pa, Pa*s, mm^3/s) on the command line and in sidecars.
  std::optional<Dimension> quantity{};
  // The command-line flag that overrides it ("--sliver-angle"), if any; "!--no-image" sets a
  // true/false setting to false.
  const char* flag = nullptr;
  // Further refusal of a value in range ("", or the whole message naming the key): a bound with a hole in it.
  std::string (*problem)(double) = nullptr;
  SettingCondition only_with{};      // given only with this choice of another setting of the table
  const char* range_unit = nullptr;  // the unit of the range when `unit` describes a list ("mm" for "[mm × 6]")
  // The fallback is the value itself ("100 mmHg", "20"): read into the field when the key is
  // absent, so the declaration alone holds the default (methods that share a setting declare
  // their own defaults).
  bool fallback_is_value = false;
};

// A rule between settings: `problem` says what is wrong with the filled Options, or "". `keys`:
// the settings it concerns, the first one present in a file naming the line of an error.
template <class Options>
struct SettingRule {
  std::vector<const char*> keys;
  std::string (*problem)(const Options&);
};

// The keys `settings` declares (of table `table` only, when given).
template <class Options>
std::set<std::string> settingKeys(const std::vector<Setting<Options>>& settings, const char* table = nullptr) {
  std::set<std::string> keys;
  for (const auto& s : settings)
    if (!table || std::string(table) == s.table) keys.insert(s.key);
  return keys;
}

namespace detail {

inline std::string choiceList(const std::vector<std::string>& choices) {
  std::string list;
  for (const auto& c : choices) list += (list.empty() ? "" : ", ") + c;
  return list;
}

// What a text setting allows: its choices, or what its meaning says.
template <class Options>
std::string allowedTexts(const Setting<Options>& s) {
  return s.choices.empty() ? std::string(s.meaning) : choiceList(s.choices);
}

}  // namespace detail

// The value of one number setting checked against its declaration; `where` names it in errors.
template <class Options>
void checkSettingNumber(const Setting<Options>& s, double v, const Where& where, const std::string& name) {
  if (!std::isfinite(v) || !s.range.holds(v))
    throw InputError(where.file, where.line, name + " = " + show(v) + " is out of range; allowed: " + s.range.text() + rangeUnit(s));
  if (s.problem)
    if (const auto why = s.problem(v); !why.empty()) throw InputError(where.file, where.line, why);
}

template <class Options>
void checkSettingChoice(const Setting<Options>& s, const std::string& v, const Where& where, const std::string& name) {
  if (s.choices.empty()) {
    if (v.empty()) throw InputError(where.file, where.line, name + " holds an empty text; allowed: " + s.meaning);
    return;
  }
  if (std::find(s.choices.begin(), s.choices.end(), v) == s.choices.end())
    throw InputError(where.file, where.line, name + " '" + v + "' is not allowed; allowed: " + detail::choiceList(s.choices));
}

namespace detail {

// A list of numbers, or of lengths "<number> <unit>", of the declared count.
template <class Options>
std::vector<double> listOfNumbers(const TomlReader& r, const toml::node* n, const Setting<Options>& s, double voxel_mm) {
  if (!s.quantity) return r.numbers(n, s.key, s.count);
  const auto* a = n->as_array();
  if (!a || (s.count && a->size() != s.count) || a->empty())
    throw InputError(r.file(), r.lineOf(n),
                     std::string(s.key) + " must be an array of " + (s.count ? std::to_string(s.count) + " " : "") + "lengths \"<number> <unit>\"");
  std::vector<double> out;
  for (const auto& e : *a) {
    const auto text = e.value<std::string>();
    if (!text)
      throw InputError(r.file(), r.lineOf(&e),
                       std::string(s.key) + " must hold strings \"<number> <unit>\"; units: " + allowedUnits(Dimension::Length));
    try {
      out.push_back(parseQuantity(*text, Dimension::Length, voxel_mm));
    } catch (const std::invalid_argument& err) { throw InputError(r.file(), r.lineOf(&e), std::string(s.key) + ": " + err.what()); }
  }
  return out;
}

// The text a string setting holds in `o` (the other side of a SettingCondition).
template <class Options>
std::string textOf(const std::vector<Setting<Options>>& settings, const Options& o, const char* key) {
  for (const auto& s : settings)
    if (std::string(s.key) == key) {
      if (const auto* m = std::get_if<std::string Options::*>(&s.field)) return o.**m;
      if (const auto* c = std::get_if<ChoiceField<Options>>(&s.field)) return c->get(o);
    }
  return {};
}

}  // namespace detail

namespace detail {

// The number a setting's fallback states ("100 mmHg", "20"), for fallback_is_value.
template <class Options>
double fallbackNumber(const Setting<Options>& s, double voxel_mm) {
  return s.quantity ? parseQuantity(s.fallback, *s.quantity, voxel_mm) : std::stod(s.fallback);
}

template <class Options>
constexpr bool isChoiceField = false;
template <class Options>
constexpr bool isChoiceField<ChoiceField<Options>> = true;

}  // namespace detail

// Fills `o` from the keys of table `t` (named `table` in the file: "tree", "tree.inlet") that
// `settings` declares for it (the table's keys are checked against them by the caller). Lengths
// take the voxel as a unit. A required setting (no fallback) missing is an error; an absent one
// whose fallback is its value gets that value.
template <class Options>
void readSettingsFrom(const TomlReader& r, const toml::table& t, const char* table, const std::vector<Setting<Options>>& settings, Options& o,
                      double voxel_mm) {
  const auto here = [&](const Setting<Options>& s) { return std::string(table) == s.table; };
  for (const auto& s : settings) {
    if (!here(s)) continue;
    const toml::node* n = t.get(s.key);
    if (!n && s.fallback) continue;
    if (!n) r.need(t, table, s.key);  // refuses: required
    const Where where = r.at(t, s.key);
    const std::string name = s.key;
    const auto number = [&] {
      const double v = s.quantity ? r.quantity(t, table, s.key, *s.quantity, voxel_mm) : r.number(t, table, s.key);
      checkSettingNumber(s, v, where, name);
      return v;
    };
    std::visit(
        [&](auto member) {
          if constexpr (detail::isChoiceField<decltype(member)>) {
            const std::string v = r.string(t, table, s.key);
            checkSettingChoice(s, v, where, name);
            member.set(o, v);
            return;
          } else {
            using T = std::remove_reference_t<decltype(o.*member)>;
            if constexpr (std::is_same_v<T, bool> || std::is_same_v<T, std::optional<bool>>) {
              o.*member = r.boolean(t, s.key, false);
            } else if constexpr (std::is_same_v<T, int> || std::is_same_v<T, std::optional<int>>) {
              const int v = r.smallInteger(t, table, s.key, std::int64_t(s.range.lo), std::int64_t(s.range.hi));
              if (s.problem)
                if (const auto why = s.problem(v); !why.empty()) throw InputError(where.file, where.line, why);
              o.*member = v;
            } else if constexpr (std::is_same_v<T, std::int64_t>) {
              const std::int64_t v = r.integer(t, table, s.key);
              checkSettingNumber(s, double(v), where, name);
              o.*member = v;
            } else if constexpr (std::is_same_v<T, double> || std::is_same_v<T, std::optional<double>>) {
              o.*member = number();
            } else if constexpr (std::is_same_v<T, std::string>) {
              const std::string v = r.string(t, table, s.key);
              checkSettingChoice(s, v, where, name);
              o.*member = v;
            } else if constexpr (std::is_same_v<T, std::vector<double>>) {
              const auto v = detail::listOfNumbers(r, n, s, voxel_mm);
              for (double x : v) checkSettingNumber(s, x, where, name + " entry");
              o.*member = v;
            } else if constexpr (std::is_same_v<T, std::optional<Vec3>>) {
              const auto v = detail::listOfNumbers(r, n, s, voxel_mm);
              for (double x : v) checkSettingNumber(s, x, where, name + " entry");
              o.*member = Vec3(v[0], v[1], v[2]);
            } else {
              static_assert(std::is_same_v<T, std::vector<std::string>>);
              const auto* a = n->as_array();
              if (!a) throw InputError(where.file, where.line, name + " must be a list of strings; allowed: " + detail::allowedTexts(s));
              std::vector<std::string> v;
              for (const auto& e : *a) {
                const auto text = e.value<std::string>();
                if (!text) throw InputError(where.file, r.lineOf(&e), name + ": '?' is not allowed; allowed: " + detail::allowedTexts(s));
                checkSettingChoice(s, *text, {where.file, r.lineOf(&e)}, name);
                v.push_back(*text);
              }
              o.*member = v;
            }
          }
        },
        s.field);
  }
  // Defaults that are values, once the choices they may depend on are read.
  for (const auto& s : settings) {
    if (!here(s) || !s.fallback_is_value || t.get(s.key)) continue;
    if (s.only_with.key && detail::textOf(settings, o, s.only_with.key) != s.only_with.value) continue;
    std::visit(
        [&](auto member) {
          if constexpr (!detail::isChoiceField<decltype(member)>) {
            using T = std::remove_reference_t<decltype(o.*member)>;
            if constexpr (std::is_same_v<T, std::string>)
              o.*member = s.fallback;
            else if constexpr (std::is_arithmetic_v<T> && !std::is_same_v<T, bool>)
              o.*member = T(detail::fallbackNumber(s, voxel_mm));
            else if constexpr (std::is_same_v<T, std::optional<double>> || std::is_same_v<T, std::optional<int>>)
              o.*member = typename T::value_type(detail::fallbackNumber(s, voxel_mm));
          } else {
            member.set(o, s.fallback);
          }
        },
        s.field);
  }
  for (const auto& s : settings) {
    if (!s.only_with.key || !here(s) || !t.get(s.key)) continue;
    const std::string chosen = detail::textOf(settings, o, s.only_with.key);
    if (chosen != s.only_with.value)
      throw InputError(r.file(), r.at(t, s.key).line,
                       std::string(s.key) + " is a parameter of " + s.only_with.key + " = \"" + s.only_with.value + "\", not of \"" + chosen +
                           "\"; set that " + s.only_with.key + " or remove the key");
  }
}

// Fills `o` from the file's table `table` (see readSettingsFrom).
template <class Options>
void readSettings(const TomlReader& r, const char* table, const std::vector<Setting<Options>>& settings, Options& o, double voxel_mm) {
  readSettingsFrom(r, r.tableOrEmpty(table), table, settings, o, voxel_mm);
}

// Refuses the first rule `o` breaks: `where(key)` says where a setting was given (a file's line),
// `fallback` where none of the rule's settings was (the table's line; none for flags).
template <class Options, class WhereOf>
void checkRules(const std::vector<SettingRule<Options>>& rules, const Options& o, WhereOf&& where, const Where& fallback = {"", 0}) {
  for (const auto& rule : rules) {
    const auto why = rule.problem(o);
    if (why.empty()) continue;
    Where w = fallback;
    for (const char* k : rule.keys)
      if (const auto at = where(k); at) {
        w = *at;
        break;
      }
    throw InputError(w.file, w.line, why);
  }
}

// One reference row per setting: table, key, unit, default, meaning (and the flag).
struct SettingRow {
  std::string table, key, unit, fallback, meaning, flag;
};

template <class Options>
std::vector<SettingRow> referenceRows(const std::vector<Setting<Options>>& settings) {
  std::vector<SettingRow> rows;
  for (const auto& s : settings) { rows.push_back({s.table, s.key, s.unit, s.fallback, s.meaning, s.flag ? s.flag : ""}); }
  return rows;
}

}  // namespace angiosynth
