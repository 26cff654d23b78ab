#pragma once
// Reading checked values from a parsed TOML table: every error names file and line, and the
// allowed values. Shared by the parameter reader and the growth methods' readers.
#include "files/toml_file.hpp"

#include <cmath>
#include <cstdint>
#include <set>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/units.hpp"
#include "core/vec3.hpp"
#include "settings/param_checks.hpp"

namespace angiosynth {

class TomlReader {
 public:
  TomlReader(const toml::table& root, std::string file) : root_(root), file_(std::move(file)) {}

  int lineOf(const toml::node* n) const { return n ? static_cast<int>(n->source().begin.line) : 0; }

  const toml::table& table(const std::string& name, const std::set<std::string>& allowed) const {
    const toml::node* n = root_.get(name);
    if (n && !n->is_table()) throw InputError(file_, lineOf(n), "[" + name + "] must be a table");
    const auto& t = tableOrEmpty(name);
    checkKeys(t, allowed, "[" + name + "]");
    return t;
  }

  // The table `name` of the root, or one shared empty table when there is none.
  const toml::table& tableOrEmpty(const std::string& name) const {
    static const toml::table empty;
    const toml::node* n = root_.get(name);
    return n && n->is_table() ? *n->as_table() : empty;
  }

  void checkKeys(const toml::table& t, const std::set<std::string>& allowed, const std::string& where) const {
    for (const auto& [k, v] : t) {
      if (allowed.count(std::string(k.str()))) continue;
      std::string list;
      for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
      throw InputError(file_, lineOf(&v), "unknown key '" + std::string(k.str()) + "' in " + where + "; allowed: " + list);
    }
  }

  const toml::node* need(const toml::table& t, const std::string& section, const std::string& key) const {
    const toml::node* n = t.get(key);
    if (!n) throw InputError(file_, lineOf(&t), "missing key '" + key + "' in [" + section + "]");
    return n;
  }

  double quantity(const toml::table& t, const std::string& section, const std::string& key, Dimension dim, double voxel_mm = 0) const {
    const toml::node* n = need(t, section, key);
    const auto s = n->value<std::string>();
    if (!s) throw InputError(file_, lineOf(n), key + " must be a string \"<number> <unit>\"; units: " + allowedUnits(dim));
    try {
      return parseQuantity(*s, dim, voxel_mm);
    } catch (const std::invalid_argument& e) { throw InputError(file_, lineOf(n), key + ": " + e.what()); }
  }

  double number(const toml::table& t, const std::string& section, const std::string& key) const {
    const toml::node* n = need(t, section, key);
    const auto v = n->value<double>();
    if (!v || n->is_string() || !std::isfinite(*v)) throw InputError(file_, lineOf(n), key + " must be a finite number");
    return *v;
  }

  std::int64_t integer(const toml::table& t, const std::string& section, const std::string& key) const {
    const toml::node* n = need(t, section, key);
    if (!n->is_integer()) throw InputError(file_, lineOf(n), key + " must be a whole number");
    return *n->value<std::int64_t>();
  }

  // A whole number checked against [lo, hi] before it is narrowed.
  int smallInteger(const toml::table& t, const std::string& section, const std::string& key, std::int64_t lo, std::int64_t hi) const {
    const std::int64_t v = integer(t, section, key);
    if (v < lo || v > hi)
      throw InputError(file_, lineOf(t.get(key)),
                       key + " = " + std::to_string(v) + " is out of range; allowed: [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
    return static_cast<int>(v);
  }

  std::string string(const toml::table& t, const std::string& section, const std::string& key) const {
    const toml::node* n = need(t, section, key);
    const auto v = n->value<std::string>();
    if (!v) throw InputError(file_, lineOf(n), key + " must be a string");
    return *v;
  }

  std::vector<double> numbers(const toml::node* n, const std::string& key, std::size_t count) const {
    const auto* arr = n->as_array();
    if (!arr || (count && arr->size() != count) || arr->empty())
      throw InputError(file_, lineOf(n), key + " must be an array of " + (count ? std::to_string(count) + " " : "") + "numbers");
    std::vector<double> out;
    for (const auto& e : *arr) {
      const auto v = e.value<double>();
      if (!v || e.is_string() || !std::isfinite(*v)) throw InputError(file_, lineOf(n), key + " must hold finite numbers only");
      out.push_back(*v);
    }
    return out;
  }

  // Keys that belong to another growth method.
  void forbid(const toml::table& t, const std::string& section, const std::set<std::string>& keys, const std::string& why) const {
    for (const auto& k : keys)
      if (const auto* n = t.get(k)) throw InputError(file_, lineOf(n), "'" + k + "' in [" + section + "] " + why);
  }

  Vec3 point(const toml::node* n, const std::string& key, bool allow_2d) const {
    const auto* arr = n->as_array();
    const std::size_t size = arr ? arr->size() : 0;
    if (!(size == 3 || (allow_2d && size == 2)))
      throw InputError(file_, lineOf(n), key + " must be an array of " + (allow_2d ? "2 or 3" : "3") + " numbers");
    const auto v = numbers(n, key, size);
    return Vec3(v[0], v[1], size == 3 ? v[2] : 0.0);
  }

  Where at(const toml::table& t, const std::string& key) const { return {file_, lineOf(t.get(key))}; }
  const std::string& file() const { return file_; }

  const toml::table& root() const { return root_; }
  // A boolean key (false when absent).
  bool boolean(const toml::table& t, const std::string& key, bool fallback) const {
    const toml::node* n = t.get(key);
    if (!n) return fallback;
    if (!n->is_boolean()) throw InputError(file_, lineOf(n), key + " must be true or false");
    return *n->value<bool>();
  }

 private:
  const toml::table& root_;
  std::string file_;
};

}  // namespace angiosynth
