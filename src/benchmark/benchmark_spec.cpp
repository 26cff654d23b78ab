// Reading a benchmark file: [benchmark] (the base dataset, methods, truth), [segment] (the
// baselines' options) and one [[ladder]] per difficulty swept.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <set>
#include <sstream>

#include "benchmark/benchmark.hpp"
#include "core/error.hpp"
#include "files/toml_file.hpp"
#include "settings/input_paths.hpp"

namespace angiosynth {
namespace {

int lineOf(const toml::node& n) { return static_cast<int>(n.source().begin.line); }

// A node as TOML text, as an override takes it.
std::string tomlText(const toml::node& n) {
  std::ostringstream o;
  n.visit([&](const auto& x) { o << x; });
  return o.str();
}

// How the report shows a value: text without its quotes.
std::string shownValue(const toml::node& n) {
  if (const auto s = n.value_exact<std::string>()) return *s;
  return tomlText(n);
}

void checkKeys(const toml::table& t, const std::set<std::string>& allowed, const std::string& where, const std::string& file) {
  for (const auto& [k, v] : t)
    if (!allowed.count(std::string(k.str()))) {
      std::string list;
      for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
      throw InputError(file, lineOf(v), "unknown key '" + std::string(k.str()) + "' in " + where + "; allowed: " + list);
    }
}

std::string text(const toml::table& t, const char* key, const std::string& file, const std::string& fallback = {}) {
  const auto* n = t.get(key);
  if (!n) return fallback;
  if (!n->is_string()) throw InputError(file, lineOf(*n), std::string(key) + " must be a string");
  return *n->value<std::string>();
}

// `set = {"tree.terminals" = 100, …}`: overrides, each with its own line.
std::vector<SpecOverride> overridesOf(const toml::node* n, const std::string& file, const std::string& where) {
  std::vector<SpecOverride> out;
  if (!n) return out;
  const auto* t = n->as_table();
  if (!t)
    throw InputError(file, lineOf(*n),
                     where + " set takes a table of values by dotted key: set = {\"tree.terminals\" = 100, \"image.voxel_size\" = \"0.4 mm\"}");
  for (const auto& [k, v] : *t) out.push_back(parseSpecOverride(std::string(k.str()) + "=" + tomlText(v), file, lineOf(v)));
  return out;
}

bool validName(const std::string& s) {
  if (s.empty() || s.size() > 64) return false;
  for (char c : s)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_') return false;
  return true;
}

void readSegmentOptions(const toml::table& t, SegmentOptions& o, const std::string& file) {
  checkKeys(t, {"sigmas_mm", "dark", "alpha", "beta", "gamma", "tau", "threshold_fraction"}, "[segment]", file);
  const auto number = [&](const char* key, double& out, double lo, double hi) {
    if (const auto* n = t.get(key)) {
      const auto v = n->value<double>();
      if (!v || !std::isfinite(*v) || *v < lo || *v > hi)
        throw InputError(file, lineOf(*n), std::string(key) + " must be a number in " + std::to_string(lo) + "…" + std::to_string(hi));
      out = *v;
    }
  };
  number("alpha", o.alpha, 1e-6, 1e6);
  number("beta", o.beta, 1e-6, 1e6);
  number("gamma", o.gamma, 0, 1e9);
  number("tau", o.tau, 1e-6, 1);
  number("threshold_fraction", o.threshold_fraction, 0, 1);
  if (const auto* n = t.get("dark")) {
    if (!n->is_boolean()) throw InputError(file, lineOf(*n), "dark must be true (vessels darker than tissue) or false");
    o.bright = !*n->value<bool>();
  }
  if (const auto* n = t.get("sigmas_mm")) {
    const auto* a = n->as_array();
    if (!a || a->empty()) throw InputError(file, lineOf(*n), "sigmas_mm takes a list of scales in mm, e.g. [0.3, 0.6, 1.2]");
    for (const auto& e : *a) {
      const auto v = e.value<double>();
      if (!v || !(*v > 0) || !std::isfinite(*v)) throw InputError(file, lineOf(*n), "sigmas_mm: every scale must be a number > 0 (mm)");
      o.sigmas_mm.push_back(*v);
    }
  }
}

BenchmarkLadder readLadder(const toml::table& t, const std::string& file) {
  BenchmarkLadder l;
  l.line = lineOf(t);
  checkKeys(t, {"name", "title", "key", "values", "labels", "set"}, "[[ladder]]", file);
  l.name = text(t, "name", file);
  if (!validName(l.name)) throw InputError(file, l.line, "a ladder needs name = \"…\": letters, digits, '-' or '_' (its directory)");
  l.key = text(t, "key", file);
  if (l.key.empty()) throw InputError(file, l.line, "ladder " + l.name + " needs key = \"…\": the value it sweeps, e.g. \"profile.gaussian.sigma\"");
  l.title = text(t, "title", file, l.key);
  const auto* v = t.get("values");
  const auto* a = v ? v->as_array() : nullptr;
  if (!a || a->size() < 2 || a->size() > 100)
    throw InputError(file, v ? lineOf(*v) : l.line, "ladder " + l.name + " needs values = [...]: 2 to 100 rungs, one value each");
  for (const auto& e : *a) {
    l.values.push_back(tomlText(e));
    l.labels.push_back(shownValue(e));
    parseSpecOverride(l.key + "=" + l.values.back(), file, lineOf(e));
  }
  if (const auto* n = t.get("labels")) {
    const auto* la = n->as_array();
    if (!la || la->size() != a->size()) throw InputError(file, lineOf(*n), "labels needs one text per value (" + std::to_string(a->size()) + ")");
    for (std::size_t i = 0; i < la->size(); ++i) {
      const auto s = la->get(i)->value<std::string>();
      if (!s) throw InputError(file, lineOf(*n), "labels must be texts");
      l.labels[i] = *s;
    }
  }
  l.fixed = overridesOf(t.get("set"), file, "ladder " + l.name + ":");
  return l;
}

}  // namespace

std::string BenchmarkLadder::rungDir(std::size_t rung) const {
  char buf[16];
  std::snprintf(buf, sizeof buf, "%02zu", rung);
  return buf;
}

std::vector<SpecOverride> BenchmarkLadder::overrides(std::size_t rung) const {
  std::vector<SpecOverride> out = fixed;
  out.push_back(parseSpecOverride(key + "=" + values.at(rung), "", line));
  return out;
}

void selectLadders(BenchmarkSpec& spec, const std::vector<std::string>& names) {
  if (names.empty()) return;
  std::string there;
  for (const auto& l : spec.ladders) there += (there.empty() ? "" : ", ") + l.name;
  for (const auto& n : names)
    if (std::none_of(spec.ladders.begin(), spec.ladders.end(), [&](const BenchmarkLadder& l) { return l.name == n; }))
      throw InputError(spec.file, 0, "no ladder named '" + n + "'; allowed: " + there);
  std::vector<BenchmarkLadder> kept;
  for (const auto& l : spec.ladders)
    if (std::find(names.begin(), names.end(), l.name) != names.end()) kept.push_back(l);
  spec.ladders = kept;
}

DatasetSpec rungDataset(const BenchmarkSpec& spec, const BenchmarkLadder& ladder, std::size_t rung) {
  std::vector<SpecOverride> all = spec.dataset_set;
  for (auto o : ladder.overrides(rung)) {
    o.file = spec.file;
    all.push_back(std::move(o));
  }
  try {
    return readDatasetSpec(spec.dataset, all);
  } catch (const InputError& e) {
    const std::string rung_is = "ladder " + ladder.name + ", rung " + ladder.rungDir(rung) + " (" + ladder.key + " = " + ladder.values[rung] + ")";
    // An error in the benchmark file itself keeps its place; one in the dataset spec or a file
    // it names is told from the ladder's line.
    if (e.file() == spec.file) {
      const std::string what = e.what(), place = spec.file + ":" + std::to_string(e.line()) + ": ";
      throw InputError(spec.file, e.line(), rung_is + ": " + (what.rfind(place, 0) == 0 ? what.substr(place.size()) : what));
    }
    throw InputError(spec.file, ladder.line, rung_is + ": " + e.what());
  }
}

BenchmarkSpec readBenchmarkSpec(const std::filesystem::path& path, const std::vector<SpecOverride>& set) {
  BenchmarkSpec s;
  const toml::table root = parseTomlFile(path, "benchmark file");
  s.file = std::filesystem::weakly_canonical(path).string();
  {
    std::ifstream in(path, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    s.text = ss.str();
  }
  checkKeys(root, {"benchmark", "segment", "ladder"}, "a benchmark file", s.file);
  const auto* b = root.get("benchmark");
  if (!b || !b->is_table()) throw InputError(s.file, 0, "a benchmark file needs a [benchmark] table (title, dataset, methods, truth)");
  const auto& bt = *b->as_table();
  checkKeys(bt, {"title", "description", "dataset", "samples", "methods", "truth", "tuned", "set"}, "[benchmark]", s.file);
  s.title = text(bt, "title", s.file, path.stem().string());
  s.description = text(bt, "description", s.file);
  const std::string dataset = text(bt, "dataset", s.file);
  if (dataset.empty()) throw InputError(s.file, lineOf(bt), "[benchmark] needs dataset = \"…\": the dataset spec every rung varies");
  s.dataset = resolveInputPath(dataset, s.file, lineOf(*bt.get("dataset")));
  s.dataset_set = overridesOf(bt.get("set"), s.file, "[benchmark]");
  if (const auto* n = bt.get("samples")) {
    const auto v = n->value_exact<std::int64_t>();
    if (!v || *v < 1 || *v > 100000) throw InputError(s.file, lineOf(*n), "samples (each rung's) must be a whole number in 1…100000");
    s.dataset_set.push_back(parseSpecOverride("dataset.samples=" + std::to_string(*v), s.file, lineOf(*n)));
  }
  std::string allowed;
  for (const auto& m : segmentMethods()) allowed += (allowed.empty() ? "" : ", ") + std::string(m.name);
  if (const auto* n = bt.get("methods")) {
    const auto* a = n->as_array();
    if (!a) throw InputError(s.file, lineOf(*n), "methods takes a list of reference segmenters; allowed: " + allowed);
    for (const auto& e : *a) {
      const auto m = e.value<std::string>();
      bool known = false;
      for (const auto& k : segmentMethods()) known |= m && *m == k.name;
      if (!known || std::find(s.methods.begin(), s.methods.end(), *m) != s.methods.end())
        throw InputError(s.file, lineOf(e), "methods: each a distinct reference segmenter; allowed: " + allowed);
      s.methods.push_back(*m);
    }
  } else {
    for (const auto& k : segmentMethods()) s.methods.push_back(k.name);
  }
  if (const auto* n = bt.get("truth")) {
    const auto v = n->value<std::string>();
    if (!v || (*v != "exact" && *v != "training"))
      throw InputError(s.file, lineOf(*n), "truth must be \"exact\" (the exact mask) or \"training\" (labelsTr, under the dataset's label policy)");
    s.truth = *v == "exact" ? DatasetTruth::Exact : DatasetTruth::Training;
  }
  if (const auto* n = bt.get("tuned")) {
    if (!n->is_boolean()) throw InputError(s.file, lineOf(*n), "tuned must be true (also each baseline at its best threshold for the rung) or false");
    s.tuned = *n->value<bool>();
  }
  if (const auto* n = root.get("segment")) {
    if (!n->is_table()) throw InputError(s.file, lineOf(*n), "[segment] is a table of the baselines' options");
    readSegmentOptions(*n->as_table(), s.segment, s.file);
  }
  const auto* ls = root.get("ladder");
  const auto* la = ls ? ls->as_array() : nullptr;
  if (!la || la->empty()) throw InputError(s.file, 0, "a benchmark needs at least one [[ladder]] (name, key, values)");
  std::set<std::string> names;
  for (const auto& e : *la) {
    if (!e.is_table()) throw InputError(s.file, lineOf(e), "ladders are written as [[ladder]] tables");
    s.ladders.push_back(readLadder(*e.as_table(), s.file));
    if (!names.insert(s.ladders.back().name).second)
      throw InputError(s.file, s.ladders.back().line, "two ladders are named " + s.ladders.back().name);
  }
  s.dataset_set.insert(s.dataset_set.end(), set.begin(), set.end());
  // Every rung reads as a dataset now, so a bad value fails before any work starts.
  for (const auto& l : s.ladders)
    for (std::size_t r = 0; r < l.values.size(); ++r) rungDataset(s, l, r);
  return s;
}

}  // namespace angiosynth
