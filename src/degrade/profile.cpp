#include "degrade/profile.hpp"

#include "files/toml_file.hpp"

#include <cstdlib>
#include <set>
#include <sstream>
#include <unistd.h>

#include "core/error.hpp"
#include "settings/input_paths.hpp"
#include "files/text_lines.hpp"

namespace angiosynth {
namespace {

int lineOf(const toml::node& n) { return static_cast<int>(n.source().begin.line); }

std::string allowedEffects() {
  std::string s;
  for (const auto* t : effectTypes()) s += (s.empty() ? "" : ", ") + std::string(t->name);
  return s;
}

// A fixed value or range without references (the profile's own intensities, probabilities).
ParamSpec plainSpec(const toml::node& n, ParamKind kind, const std::string& name, const std::string& file) {
  ParamSpec s = readParamSpec(n, kind, name, file);
  for (const auto& c : s.components)
    if (c.lo.ref != Amount::Ref::Plain || c.hi.ref != Amount::Ref::Plain)
      throw InputError(file, lineOf(n), name + " must be a number or a range of numbers");
  return s;
}

EffectSpec readEffect(const toml::table& t, const std::string& file, bool& has_warp) {
  EffectSpec e;
  e.line = lineOf(t);
  const auto* type = t.get("type");
  if (!type || !type->is_string()) throw InputError(file, e.line, "an [[effect]] needs type = \"<name>\"; allowed: " + allowedEffects());
  const std::string name = *type->value<std::string>();
  e.type = findEffectType(name);
  if (!e.type) throw InputError(file, lineOf(*type), "unknown effect '" + name + "'; allowed: " + allowedEffects());
  if (e.type->moves_geometry) {
    if (has_warp) throw InputError(file, e.line, "a profile may hold one warp; merge them into one");
    has_warp = true;
  }
  for (const auto& [k, v] : t) {
    const std::string key(k.str());
    if (key == "type") continue;
    if (key == "probability") {
      e.probability = plainSpec(v, ParamKind::Probability, "probability", file);
      continue;
    }
    const ParamDecl* decl = nullptr;
    for (const auto& d : e.type->params)
      if (key == d.name) decl = &d;
    if (!decl) {
      std::string list = "probability";
      for (const auto& d : e.type->params) list += std::string(", ") + d.name;
      throw InputError(file, lineOf(v), "unknown parameter '" + key + "' of effect " + name + "; allowed: " + list);
    }
    e.params[key] = readParamSpec(v, decl->kind, key, file);
  }
  for (const auto& d : e.type->params)
    if (!d.fallback && !e.params.count(d.name))
      throw InputError(file, e.line, std::string("effect ") + name + " needs " + d.name + " (" + d.meaning + ")");
  return e;
}

}  // namespace

Profile readProfileToml(const std::filesystem::path& path) {
  const std::string file = path.string();
  const toml::table root = parseTomlFile(path, "profile file");
  Profile p;
  p.name = path.stem().string();
  p.file = file;
  static const std::set<std::string> keys{"description", "background", "vessel", "dtype", "clamp_each_step", "effect"};
  for (const auto& [k, v] : root)
    if (!keys.count(std::string(k.str())))
      throw InputError(file, lineOf(v),
                       "unknown key '" + std::string(k.str()) + "'; allowed: description, background, vessel, dtype, clamp_each_step, [[effect]]");
  if (const auto* n = root.get("description")) p.description = n->value_or<std::string>("");
  if (const auto* n = root.get("background")) p.background = plainSpec(*n, ParamKind::Intensity, "background", file);
  if (const auto* n = root.get("vessel")) p.vessel = plainSpec(*n, ParamKind::Intensity, "vessel", file);
  if (const auto* n = root.get("dtype")) {
    p.dtype = n->value_or<std::string>("");
    if (p.dtype != "uint8" && p.dtype != "uint16" && p.dtype != "int16" && p.dtype != "float32")
      throw InputError(file, lineOf(*n), "dtype '" + p.dtype + "'; allowed: uint8, uint16, int16, float32");
  }
  if (const auto* n = root.get("clamp_each_step")) {
    if (!n->is_boolean()) throw InputError(file, lineOf(*n), "clamp_each_step must be true or false");
    p.clamp_each_step = *n->value<bool>();
  }
  bool has_warp = false;
  if (const auto* n = root.get("effect")) {
    const auto* arr = n->as_array();
    if (!arr) throw InputError(file, lineOf(*n), "effects are written as [[effect]] tables");
    for (const auto& e : *arr) {
      if (!e.is_table()) throw InputError(file, lineOf(e), "effects are written as [[effect]] tables");
      p.effects.push_back(readEffect(*e.as_table(), file, has_warp));
    }
  }
  return p;
}

Profile readVascuSynthNoiseFile(const std::filesystem::path& path) {
  const std::string file = path.string();
  Profile p;
  p.name = path.stem().string();
  p.file = file;
  p.description = "VascuSynth noise file";
  p.background = fixedParam(0, file, 0);
  p.vessel = fixedParam(255, file, 0);
  p.dtype = "uint8";
  p.clamp_each_step = true;
  struct Directive {
    const char* key;
    const char* type;
    std::vector<const char*> params;
    const char* usage;
  };
  static const Directive directives[] = {
      {"GAUSSIAN", "gaussian", {"mean", "sigma"}, "GAUSSIAN: <median> <sigma>"},
      {"UNIFORM", "uniform", {"low", "high"}, "UNIFORM: <lower bound> <upper bound>"},
      {"SALTPEPPER",
       "impulse",
       {"salt_value", "salt_probability", "pepper_value", "pepper_probability"},
       "SALTPEPPER: <salt value> <salt probability> <pepper value> <pepper probability>"},
      {"SHADOW", "shadow", {"count"}, "SHADOW: <number of shadows>"},
  };
  const std::string allowed = "GAUSSIAN:, UNIFORM:, SALTPEPPER:, SHADOW:";
  for (const auto& line : readTextLines(path, "noise file")) {
    const auto colon = line.text.find(':');
    const std::string key = trimmed(line.text.substr(0, colon));
    const Directive* d = nullptr;
    for (const auto& c : directives)
      if (colon != std::string::npos && key == c.key) d = &c;
    if (!d) {
      const auto words = splitWords(line.text);
      const std::string first = words.empty() ? "" : words[0];
      std::string hint;
      if (first == "SALTPEPER" || first == "SALTPEPER:")
        hint = " (VascuSynth ignores this misspelling silently; did you mean SALTPEPPER:?)";
      else if (colon == std::string::npos)
        hint = " (a directive ends with ':')";
      throw InputError(file, line.number, "unknown noise directive '" + first + "'" + hint + "; allowed: " + allowed);
    }
    const auto words = splitWords(line.text.substr(colon + 1));
    if (words.size() != d->params.size())
      throw InputError(
          file, line.number,
          std::string(d->key) + " takes " + std::to_string(d->params.size()) + " value" + (d->params.size() == 1 ? "" : "s") + "; write " + d->usage);
    EffectSpec e;
    e.type = findEffectType(d->type);
    e.line = line.number;
    for (std::size_t i = 0; i < words.size(); ++i) {
      const double v = std::string(d->key) == "SHADOW"
                           ? static_cast<double>(parseInteger(words[i], file, line.number, std::string(d->key) + " count"))
                           : parseNumber(words[i], file, line.number, std::string(d->key) + " " + d->params[i]);
      e.params[d->params[i]] = fixedParam(v, file, line.number);
    }
    p.effects.push_back(std::move(e));
  }
  return p;
}

std::vector<std::filesystem::path> profileSearchPath() {
  std::vector<std::filesystem::path> dirs;
  if (const char* env = std::getenv("ANGIOSYNTH_PROFILE_PATH")) {
    std::stringstream ss(env);
    for (std::string d; std::getline(ss, d, ':');)
      if (!d.empty()) dirs.emplace_back(d);
  }
  // Beside an installed binary (prefix/bin → prefix/share/angiosynth/noise_profiles).
  char exe[4096];
  const ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
  if (n > 0) {
    exe[n] = 0;
    dirs.push_back(std::filesystem::path(exe).parent_path().parent_path() / "share/angiosynth/noise_profiles");
  }
#ifdef ANGIOSYNTH_SOURCE_PROFILES
  dirs.emplace_back(ANGIOSYNTH_SOURCE_PROFILES);
#endif
  return dirs;
}

Profile loadProfile(const std::string& ref, const std::filesystem::path& named_in, int line) {
  const std::filesystem::path r(ref);
  const bool bare = !r.has_parent_path() && !r.has_extension();
  if (bare) {
    const auto dirs = profileSearchPath();
    std::string looked, names;
    for (const auto& d : dirs) {
      const auto f = d / (ref + ".toml");
      if (std::filesystem::exists(f)) return readProfileToml(f);
      looked += (looked.empty() ? "" : ", ") + d.string();
    }
    for (const auto& d : dirs) {
      std::error_code ec;
      for (const auto& e : std::filesystem::directory_iterator(d, ec))
        if (e.path().extension() == ".toml") names += (names.empty() ? "" : ", ") + e.path().stem().string();
      if (!names.empty()) break;
    }
    throw InputError(named_in.string(), line,
                     "no profile named '" + ref + "' (looked in " + looked + "); shipped: " + names +
                         "; or give a path to a .toml profile or a VascuSynth noise file");
  }
  const auto path = resolveInputPath(r, named_in, line);
  if (path.extension() == ".toml") return readProfileToml(path);
  return readVascuSynthNoiseFile(path);
}

void overrideProfileValue(Profile& p, const std::string& key, const toml::node& value, const std::string& file) {
  const int line = lineOf(value);
  if (key == "background" || key == "vessel") {
    (key == "background" ? p.background : p.vessel) = plainSpec(value, ParamKind::Intensity, key, file);
    return;
  }
  const auto dot = key.find('.');
  const std::string type = key.substr(0, dot), param = dot == std::string::npos ? "" : key.substr(dot + 1);
  std::string present;
  int changed = 0;
  for (auto& e : p.effects) {
    present += (present.empty() ? "" : ", ") + std::string(e.type->name);
    if (e.type->name != type) continue;
    const ParamDecl* decl = nullptr;
    for (const auto& d : e.type->params)
      if (param == d.name) decl = &d;
    if (param == "probability") {
      e.probability = plainSpec(value, ParamKind::Probability, "probability", file);
    } else if (decl) {
      e.params[param] = readParamSpec(value, decl->kind, param, file);
    } else {
      std::string list = "probability";
      for (const auto& d : e.type->params) list += std::string(", ") + d.name;
      throw InputError(file, line, "profile." + key + ": effect " + type + " has no parameter '" + param + "'; allowed: " + list);
    }
    ++changed;
  }
  if (!changed)
    throw InputError(file, line,
                     "profile." + key + ": the profile " + p.name + " has no effect '" + type + "'; allowed: profile.background, profile.vessel, " +
                         "profile.<effect>.<parameter> with an effect of the profile (" + (present.empty() ? "none" : present) + ")");
}

}  // namespace angiosynth
