#include "dataset/spec.hpp"

#include "core/format.hpp"

#include <toml++/toml.h>

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <cmath>
#include <map>
#include <numeric>
#include <optional>
#include <set>
#include <fstream>
#include <sstream>

#include "core/error.hpp"
#include "core/rng.hpp"
#include "dataset/manifest.hpp"
#include "degrade/profile.hpp"
#include "grow/method.hpp"
#include "config/scenario.hpp"

namespace angiosynth {
namespace {

int lineOf(const toml::node& n) { return static_cast<int>(n.source().begin.line); }

const char* const kDistributions[] = {"uniform", "log_uniform", "normal", "integer", "choice"};

// Parameter files use no inline tables of their own, so an inline table stands where a value
// goes: a distribution, perhaps misspelt ({unifrom = …}), which draw() then names.
bool isDistribution(const toml::node& n) {
  const auto* t = n.as_table();
  if (!t) return false;
  if (t->is_inline()) return true;
  for (const char* d : kDistributions)
    if (t->contains(d)) return true;
  return false;
}

// A number, or a quantity string "<number> <unit>": the number and the unit.
struct Quantity {
  double value = 0;
  std::string unit;  // empty for a plain number
  bool integer = false;
};

// toml++'s value<int64_t>() converts a float node by a cast that is undefined
// beyond the int64 range (found by fuzzing), so only integer nodes are read.
std::optional<std::int64_t> wholeNumber(const toml::node& n) {
  if (!n.is_integer()) return std::nullopt;
  return n.as_integer()->get();
}

Quantity quantityOf(const toml::node& n, const std::string& file, const std::string& what) {
  Quantity q;
  if (n.is_integer()) {
    q.value = double(*n.value<std::int64_t>());
    q.integer = true;
    return q;
  }
  if (n.is_floating_point()) {
    q.value = *n.value<double>();
    if (!std::isfinite(q.value)) throw InputError(file, lineOf(n), what + " bounds must be finite numbers");
    return q;
  }
  if (const auto s = n.value_exact<std::string>()) {
    std::istringstream in(*s);
    if (in >> q.value && std::isfinite(q.value)) {
      std::getline(in >> std::ws, q.unit);
      return q;
    }
  }
  throw InputError(file, lineOf(n), what + " bounds must be numbers or quantities \"<number> <unit>\"");
}

// A drawn value as a node that remembers the distribution's line, so that errors about the
// resolved parameters (a draw out of range, say) still point into the spec: the value is parsed
// from text placed on that line.
std::unique_ptr<toml::node> valueOf(double v, const std::string& unit, bool integer, int line) {
  char buf[64];
  if (integer)
    std::snprintf(buf, sizeof buf, "%lld", static_cast<long long>(v));
  else
    std::snprintf(buf, sizeof buf, "%.17g", v);
  std::string text = buf;
  if (!unit.empty())
    text = "\"" + text + " " + unit + "\"";
  else if (!integer && text.find_first_of(".en") == std::string::npos)
    text += ".0";  // stays a float
  toml::table t = toml::parse(std::string(std::max(0, line - 1), '\n') + "v = " + text);
  std::unique_ptr<toml::node> out;  // moved, not copied: a copy would lose the line
  t.get("v")->visit([&](auto& x) { out = std::make_unique<std::decay_t<decltype(x)>>(std::move(x)); });
  return out;
}

// Draws one value of a distribution node.
std::unique_ptr<toml::node> draw(const toml::table& d, Rng& rng, const std::string& file) {
  const int line = lineOf(d);
  const auto bounds = [&](const char* key, Quantity& a, Quantity& b) {
    const auto* arr = d.get(key)->as_array();
    if (!arr || arr->size() != 2) throw InputError(file, line, std::string(key) + " takes [a, b]");
    a = quantityOf(*arr->get(0), file, key);
    b = quantityOf(*arr->get(1), file, key);
    if (a.unit != b.unit) throw InputError(file, line, std::string(key) + ": both bounds need the same unit");
  };
  int kinds = 0;
  for (const auto& [k, v] : d) {
    // min and max belong to normal, weights to choice.
    bool known = ((k == "min" || k == "max") && d.contains("normal")) || (k == "weights" && d.contains("choice"));
    for (const char* name : kDistributions) known |= k == name, kinds += k == name;
    if (!known)
      throw InputError(file, lineOf(v),
                       "unknown key '" + std::string(k.str()) +
                           "' in a distribution; allowed: uniform, log_uniform, normal (with min, max), "
                           "integer, choice (with weights)");
  }
  if (kinds != 1) throw InputError(file, line, "a distribution names exactly one of uniform, log_uniform, normal, integer, choice");
  const double u = rng.uniform();
  Quantity a, b;
  if (d.contains("uniform")) {
    bounds("uniform", a, b);
    if (a.value > b.value) throw InputError(file, line, "uniform: a > b");
    return valueOf(a.value + u * (b.value - a.value), a.unit, false, line);
  }
  if (d.contains("log_uniform")) {
    bounds("log_uniform", a, b);
    if (!(a.value > 0 && b.value >= a.value)) throw InputError(file, line, "log_uniform needs 0 < a <= b");
    return valueOf(std::exp(std::log(a.value) + u * (std::log(b.value) - std::log(a.value))), a.unit, false, line);
  }
  if (d.contains("integer")) {
    bounds("integer", a, b);
    constexpr double kExact = 9007199254740992.0;  // 2^53: whole numbers a double holds exactly
    if (!a.integer || !b.integer || a.value > b.value || std::abs(a.value) > kExact || std::abs(b.value) > kExact)
      throw InputError(file, line, "integer takes whole numbers [a, b] with a <= b, each within ±2^53");
    const double span = b.value - a.value + 1;
    return valueOf(std::min(b.value, a.value + std::floor(u * span)), a.unit, true, line);
  }
  if (d.contains("normal")) {
    bounds("normal", a, b);
    const double lo = d.contains("min") ? quantityOf(*d.get("min"), file, "min").value : -INFINITY;
    const double hi = d.contains("max") ? quantityOf(*d.get("max"), file, "max").value : INFINITY;
    if (!(b.value >= 0) || lo > hi) throw InputError(file, line, "normal takes [mean, sd] with sd >= 0 and min <= max");
    // Truncated by rejection; a truncation that rejects nearly everything is a spec error.
    for (int tries = 0; tries < 10000; ++tries) {
      const double x = a.value + b.value * rng.normal();
      if (x >= lo && x <= hi) return valueOf(x, a.unit, false, line);
    }
    throw InputError(file, line, "normal: min and max leave almost no probability; widen them");
  }
  const auto* arr = d.get("choice")->as_array();
  if (!arr || arr->empty()) throw InputError(file, line, "choice takes a non-empty array of values");
  std::vector<double> w(arr->size(), 1.0);
  if (const auto* wn = d.get("weights")) {
    const auto* wa = wn->as_array();
    if (!wa || wa->size() != arr->size()) throw InputError(file, lineOf(*wn), "weights needs one number per choice");
    for (std::size_t i = 0; i < w.size(); ++i) {
      const auto x = wa->get(i)->value<double>();
      if (!x || *x < 0) throw InputError(file, lineOf(*wn), "weights must be numbers >= 0");
      w[i] = *x;
    }
  }
  const double total = std::accumulate(w.begin(), w.end(), 0.0);
  if (!(total > 0)) throw InputError(file, line, "weights must not all be 0");
  double x = u * total;
  std::size_t pick = 0;
  while (pick + 1 < w.size() && x >= w[pick]) x -= w[pick++];
  std::unique_ptr<toml::node> out;
  arr->get(pick)->visit([&](const auto& v) { out = std::make_unique<std::decay_t<decltype(v)>>(v); });
  return out;
}

// Replaces every distribution in `t` by a draw, in the table's (sorted) key order.
void resolveTable(toml::table& t, Rng& rng, const std::string& file) {
  for (auto&& [k, v] : t) {
    if (isDistribution(v)) {
      auto drawn = draw(*v.as_table(), rng, file);
      const toml::key key = k;  // (clang 14 cannot capture a structured binding)
      drawn->visit([&](auto& x) { t.insert_or_assign(key, std::move(x)); });
    } else if (auto* sub = v.as_table()) {
      resolveTable(*sub, rng, file);
    }
  }
}

// An override's value as a node on the line it was written on (for errors that cite it).
toml::table overrideValue(const SpecOverride& o) {
  try {
    return toml::parse(std::string(std::max(0, o.line - 1), '\n') + "v = " + o.value, std::string_view(o.file));
  } catch (const toml::parse_error& e) {
    throw InputError(o.file, o.line,
                     o.key + " = " + o.value + ": not a TOML value (" + std::string(e.description()) + "); quote text and quantities: \"0.3 mm\"");
  }
}

bool profileOverride(const SpecOverride& o) { return o.key.rfind("profile.", 0) == 0; }

// Sets t[a][b]…[key] = value, making the tables on the way. `profile_too` also places the
// profile's overrides (under a table "profile": for hashes and comparisons, not for samples).
void applyOverrides(toml::table& root, const std::vector<SpecOverride>& overrides, bool profile_too) {
  for (const auto& o : overrides) {
    if (profileOverride(o) && !profile_too) continue;
    toml::table* t = &root;
    std::string rest = o.key;
    for (auto dot = rest.find('.'); dot != std::string::npos; dot = rest.find('.')) {
      const std::string part = rest.substr(0, dot);
      rest = rest.substr(dot + 1);
      if (!t->contains(part)) t->insert(part, toml::table{});
      t = t->get(part)->as_table();
      if (!t || t->is_inline())
        throw InputError(o.file, o.line, o.key + ": " + part + " is a value in the spec, not a table; allowed: the dotted key of a value");
    }
    if (rest.empty()) throw InputError(o.file, o.line, "the key '" + o.key + "' is empty after a dot; allowed: a dotted key such as tree.terminals");
    toml::table v = overrideValue(o);
    v.get("v")->visit([&](auto& x) { t->insert_or_assign(rest, std::move(x)); });
  }
}

bool validName(const std::string& s) {
  if (s.empty()) return false;
  for (char c : s)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_') return false;
  return true;
}

// [dataset] labels and kinds.
void readLabels(const toml::table& d, DatasetSpec& s) {
  if (const auto* l = d.get("labels")) {
    const auto v = l->value<std::string>();
    if (!v || (*v != "binary" && *v != "kind"))
      throw InputError(s.file, lineOf(*l), "labels must be \"binary\" (vessel 1) or \"kind\" (one label per kind: artery, vein, ...)");
    s.labels = *v;
    s.labels_line = lineOf(*l);
  }
  const auto* k = d.get("kinds");
  if (!k) {
    if (s.labels == "kind") s.kinds = {"artery", "vein"};
    return;
  }
  if (s.labels != "kind") throw InputError(s.file, lineOf(*k), "kinds numbers the labels of labels = \"kind\"; add that, or remove kinds");
  const auto* a = k->as_array();
  const auto allowed = "kinds must be a list of distinct kind names, e.g. [\"artery\", \"vein\"] (labels 1, 2, ...; at most 255)";
  if (!a || a->empty() || a->size() > 255) throw InputError(s.file, lineOf(*k), allowed);
  for (const auto& e : *a) {
    const auto name = e.value<std::string>();
    if (!name || name->empty() || std::find(s.kinds.begin(), s.kinds.end(), *name) != s.kinds.end()) throw InputError(s.file, lineOf(*k), allowed);
    s.kinds.push_back(*name);
  }
  s.labels_line = lineOf(*k);
}

// [image] label_policy as the dataset sees it: one plain policy for every sample. Unset, a
// dataset with a degraded image labels what that image shows ("visible"): a network cannot learn
// vessels the noise hides, and labels of them teach it to guess.
void readLabelPolicy(const toml::table& root, DatasetSpec& s) {
  const auto* im = root.get("image");
  const auto* n = im && im->is_table() ? im->as_table()->get("label_policy") : nullptr;
  if (!n) {
    const auto* ds = root.get("dataset");
    const auto* profile = ds && ds->is_table() ? ds->as_table()->get("profile") : nullptr;
    const bool clean = !profile || profile->value<std::string>() == std::optional<std::string>("clean");
    s.label_policy = clean ? "binary" : "visible";
    s.label_policy_by_default = true;
    return;
  }
  const auto v = n->value<std::string>();
  if (!v)
    throw InputError(s.file, lineOf(*n),
                     "label_policy must be one policy for the whole dataset (a string, not a distribution): "
                     "binary, threshold, visible, soft or ignore");
  s.label_policy = *v;  // the parameter reader checks the name
  if (s.label_policy == "soft" && s.labels == "kind")
    throw InputError(s.file, lineOf(*n),
                     "label_policy = \"soft\" gives one float label (the partial volume); it cannot number kinds: "
                     "use labels = \"binary\" or another policy");
  if (s.label_policy == "ignore" && s.kinds.size() >= 255)
    throw InputError(s.file, lineOf(*n), "label_policy = \"ignore\" needs a label after the last kind; allowed: at most 254 kinds");
}

}  // namespace

nlohmann::ordered_json labelValues(const DatasetSpec& spec) {
  nlohmann::ordered_json j{{"background", 0}};
  if (spec.labels != "kind") j["vessel"] = 1;
  for (std::size_t i = 0; i < spec.kinds.size(); ++i) j[spec.kinds[i]] = i + 1;
  // nnU-Net v2: the ignore label is the highest, named "ignore".
  if (spec.label_policy == "ignore") j["ignore"] = spec.kinds.empty() ? 2 : spec.kinds.size() + 1;
  return j;
}

DatasetSpec readDatasetSpec(const std::filesystem::path& path, const std::vector<SpecOverride>& overrides) {
  DatasetSpec s;
  s.overrides = overrides;
  s.file = path.string();
  if (!std::filesystem::exists(path)) throw InputError(s.file, 0, "no such dataset spec");
  if (!std::filesystem::is_regular_file(path)) throw InputError(s.file, 0, "the dataset spec is not a regular file (a directory or device)");
  // One spelling of the spec's path, so every run (any working directory) records the same bytes.
  s.file = std::filesystem::weakly_canonical(path).string();
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  s.text = ss.str();
  auto root = std::make_shared<toml::table>();
  try {
    *root = toml::parse(s.text, s.file);
  } catch (const toml::parse_error& e) {
    throw InputError(s.file, static_cast<int>(e.source().begin.line), std::string("not valid TOML: ") + std::string(e.description()));
  }
  applyOverrides(*root, s.overrides, false);
  const auto* ds = root->get("dataset");
  if (!ds || !ds->is_table()) throw InputError(s.file, 0, "a dataset spec needs a [dataset] table (name, id, samples, seed)");
  const auto& d = *ds->as_table();
  for (const auto& [k, v] : d)
    if (k != "name" && k != "id" && k != "samples" && k != "seed" && k != "profile" && k != "channel_name" && k != "labels" && k != "kinds" &&
        k != "previews" && k != "licence" && k != "record_host")
      throw InputError(s.file, lineOf(v),
                       "unknown key '" + std::string(k.str()) +
                           "' in [dataset]; allowed: name, id, samples, seed, profile, channel_name, labels, kinds, previews, "
                           "licence, record_host");
  const auto need = [&](const char* key) -> const toml::node& {
    const auto* n = d.get(key);
    if (!n) throw InputError(s.file, lineOf(d), std::string("missing key '") + key + "' in [dataset]");
    return *n;
  };
  s.name = need("name").value_or<std::string>("");
  if (!validName(s.name)) throw InputError(s.file, lineOf(need("name")), "name must be letters, digits, '-' or '_' (no dots or spaces)");
  const auto id = wholeNumber(need("id"));
  if (!id || *id < 1 || *id > 999) throw InputError(s.file, lineOf(need("id")), "id must be a whole number in 1…999 (nnU-Net's DatasetNNN)");
  s.id = static_cast<int>(*id);
  const auto n = wholeNumber(need("samples"));
  if (!n || *n < 1 || *n > 100000000) throw InputError(s.file, lineOf(need("samples")), "samples must be a whole number in 1…10^8");
  s.samples = *n;
  const auto seed = wholeNumber(need("seed"));
  if (!seed || *seed < 0) throw InputError(s.file, lineOf(need("seed")), "seed must be a whole number >= 0");
  s.seed = static_cast<std::uint64_t>(*seed);
  if (const auto* c = d.get("channel_name")) {
    if (!c->is_string()) throw InputError(s.file, lineOf(*c), "channel_name must be a string (nnU-Net's channel name, e.g. \"CT\")");
    s.channel_name = *c->value<std::string>();
  }
  readLabels(d, s);
  readLabelPolicy(*root, s);
  if (const auto* p = d.get("previews")) {
    if (!p->is_boolean()) throw InputError(s.file, lineOf(*p), "previews must be true or false (MIPs of each sample in groundtruth/)");
    s.previews = *p->value<bool>();
  }
  if (const auto* l = d.get("licence")) {
    const auto v = l->value<std::string>();
    if (!v || v->empty() || v->size() > 200)
      throw InputError(s.file, lineOf(*l),
                       "licence must be a text of 1 to 200 characters: the generated data's licence, e.g. \"CC0-1.0\" or \"CC-BY-4.0\"");
    s.licence = *v;
  }
  if (const auto* h = d.get("record_host")) {
    if (!h->is_boolean()) throw InputError(s.file, lineOf(*h), "record_host must be true or false (host names in provenance.json)");
    s.record_host = *h->value<bool>();
  }
  s.sha256 = canonicalSpecSha256(s.text, s.file, s.overrides);
  if (root->contains("seed")) throw InputError(s.file, lineOf(*root->get("seed")), "the seed of a dataset goes in [dataset]");
  // Resolve and read one sample now, so a bad spec fails before any work starts.
  const ResolvedSample first = resolveSample(s, 0);
  readTomlParameters(*first.table, s.file);
  sampleProfile(s, first.profile);
  return s;
}

SpecOverride parseSpecOverride(const std::string& assignment, const std::string& file, int line) {
  const auto eq = assignment.find('=');
  const auto trim = [](std::string x) {
    x.erase(0, x.find_first_not_of(" \t"));
    x.erase(x.find_last_not_of(" \t") + 1);
    return x;
  };
  SpecOverride o{eq == std::string::npos ? "" : trim(assignment.substr(0, eq)), eq == std::string::npos ? "" : trim(assignment.substr(eq + 1)), file,
                 line};
  bool key_ok = !o.key.empty() && o.key.front() != '.' && o.key.back() != '.' && o.key.find("..") == std::string::npos;
  for (char c : o.key) key_ok &= std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.';
  if (!key_ok || o.value.empty())
    throw InputError(file, line,
                     "'" + assignment + "' is not key=value; allowed: a dotted key of the spec and a TOML value, e.g. tree.terminals=200");
  overrideValue(o);
  return o;
}

nlohmann::json overridesJson(const std::vector<SpecOverride>& overrides) {
  nlohmann::json j = nlohmann::json::array();
  for (const auto& o : overrides) j.push_back({{"key", o.key}, {"value", o.value}});
  return j;
}

std::vector<SpecOverride> overridesFromJson(const nlohmann::json& j, const std::string& file) {
  std::vector<SpecOverride> out;
  if (j.is_null()) return out;
  if (!j.is_array()) throw InputError(file, 0, "overrides must be a list of {key, value}");
  for (const auto& e : j) {
    if (!e.is_object() || !e.contains("key") || !e["key"].is_string() || !e.contains("value") || !e["value"].is_string())
      throw InputError(file, 0, "overrides must be a list of {key, value} strings");
    out.push_back({e["key"].get<std::string>(), e["value"].get<std::string>(), file, 0});
  }
  return out;
}

Profile sampleProfile(const DatasetSpec& spec, const std::string& profile_ref) {
  Profile p = loadProfile(profile_ref, spec.file, 0);
  for (const auto& o : spec.overrides)
    if (profileOverride(o)) {
      const toml::table v = overrideValue(o);
      overrideProfileValue(p, o.key.substr(8), *v.get("v"), o.file);
    }
  return p;
}

std::string sampleId(const DatasetSpec& spec, std::int64_t index) {
  int width = 4;
  for (std::int64_t n = spec.samples - 1; n >= 10000; n /= 10) ++width;
  char buf[32];
  std::snprintf(buf, sizeof buf, "%0*lld", width, static_cast<long long>(index));
  return spec.name + "_" + buf;
}

std::string datasetDirName(const DatasetSpec& spec) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "Dataset%03d_", spec.id);
  return buf + spec.name;
}

std::string readableParameters(const ResolvedSample& r) {
  const std::string& in = r.toml;
  std::string out;
  const auto digit = [](char c) { return c >= '0' && c <= '9'; };
  std::size_t i = 0;
  while (i < in.size()) {
    // A number starts at a digit not preceded by a letter, digit, '_' or '.'.
    const bool starts = digit(in[i]) && (i == 0 || !(std::isalnum(static_cast<unsigned char>(in[i - 1])) || in[i - 1] == '_' || in[i - 1] == '.'));
    if (!starts) {
      out += in[i++];
      continue;
    }
    std::size_t j = i;
    while (j < in.size() && digit(in[j])) ++j;
    std::size_t decimals = 0;
    if (j < in.size() && in[j] == '.')
      for (++j; j < in.size() && digit(in[j]); ++j) ++decimals;
    if (j < in.size() && (in[j] == 'e' || in[j] == 'E')) {
      std::size_t k = j + 1;
      if (k < in.size() && (in[k] == '+' || in[k] == '-')) ++k;
      if (k < in.size() && digit(in[k])) {
        j = k;
        while (j < in.size() && digit(in[j])) ++j;
      }
    }
    const std::string token = in.substr(i, j - i);
    std::string shorter = token;
    if (decimals >= 10 && (j == in.size() || !(std::isalnum(static_cast<unsigned char>(in[j])) || in[j] == '_'))) {
      const double v = std::strtod(token.c_str(), nullptr);
      shorter = exactNumber(v);
      if (shorter.find_first_of(".e") == std::string::npos) shorter += ".0";  // stays a float
      if (std::strtod(shorter.c_str(), nullptr) != v || shorter.size() >= token.size()) shorter = token;
    }
    out += shorter;
    i = j;
  }
  return out;
}

ResolvedSample resolveSample(const DatasetSpec& spec, std::int64_t index) {
  ResolvedSample r;
  r.index = index;
  r.id = sampleId(spec, index);
  r.seed = Rng(spec.seed, static_cast<std::uint64_t>(index), Stage::Dataset, 0).nextU64() >> 1;  // fits TOML's int64
  Rng rng(spec.seed, static_cast<std::uint64_t>(index), Stage::Dataset, 1);
  // Parsed afresh, not copied: toml++ drops source lines on copy, and errors about a sample's
  // values must point into the spec.
  auto t = std::make_shared<toml::table>(toml::parse(spec.text, std::string_view(spec.file)));
  applyOverrides(*t, spec.overrides, false);
  r.profile = "clean";
  auto& dataset = *t->get("dataset")->as_table();
  if (dataset.contains("profile")) {
    resolveTable(dataset, rng, spec.file);  // only the profile may be a distribution there
    const auto v = dataset.get("profile")->value<std::string>();
    if (!v) throw InputError(spec.file, lineOf(*dataset.get("profile")), "profile must be a profile name or file (or a choice of them)");
    r.profile = *v;
  }
  t->erase("dataset");
  resolveTable(*t, rng, spec.file);
  if (spec.label_policy_by_default && spec.label_policy != "binary") {
    if (!t->contains("image")) t->insert("image", toml::table{});
    t->get("image")->as_table()->insert_or_assign("label_policy", spec.label_policy);
  }
  t->insert_or_assign("seed", static_cast<std::int64_t>(r.seed));
  std::ostringstream o;
  o << *t << "\n";
  r.toml = o.str();
  // The label numbering changes labelsTr: a kind-labelled sample depends on it (binary samples
  // hash as they always did).
  std::string labels;
  if (spec.labels == "kind")
    for (const auto& k : spec.kinds) labels += (labels.empty() ? "labels by kind: " : ", ") + k;
  // The profile's overrides change the image; samples without any hash as they always did.
  std::string profile_overrides;
  for (const auto& o : spec.overrides)
    if (profileOverride(o)) profile_overrides += "image profile override: " + o.key + " = " + o.value + "\n";
  r.sha256 = sha256Text(r.toml + "\nimage profile: " + r.profile + "\n" + (labels.empty() ? "" : labels + "\n") + profile_overrides);
  r.table = t;
  return r;
}

namespace {

toml::table parseSpecText(const std::string& text, const std::string& file) {
  try {
    return toml::parse(text, file);
  } catch (const toml::parse_error& e) {
    throw InputError(file, static_cast<int>(e.source().begin.line), std::string("not valid TOML: ") + std::string(e.description()));
  }
}

void flatten(const toml::table& t, const std::string& prefix, std::map<std::string, std::string>& out) {
  for (const auto& [k, v] : t) {
    const std::string key = prefix.empty() ? std::string(k.str()) : prefix + "." + std::string(k.str());
    if (const auto* sub = v.as_table(); sub && !sub->is_inline()) {
      flatten(*sub, key, out);
      continue;
    }
    std::ostringstream o;
    v.visit([&](const auto& x) { o << x; });
    out[key] = o.str();
  }
}

std::map<std::string, std::string> flatSpec(const std::string& text, const std::string& file, const std::vector<SpecOverride>& overrides) {
  toml::table t = parseSpecText(text, file);
  applyOverrides(t, overrides, true);
  std::map<std::string, std::string> flat;
  flatten(t, "", flat);
  return flat;
}

}  // namespace

std::string canonicalSpecSha256(const std::string& text, const std::string& file, const std::vector<SpecOverride>& overrides) {
  const auto flat = flatSpec(text, file, overrides);
  std::string canonical;
  for (const auto& [k, v] : flat) canonical += k + " = " + v + "\n";
  return sha256Text(canonical);
}

std::vector<std::string> changedSpecKeys(const std::string& old_text, const std::string& new_text, const std::vector<SpecOverride>& old_overrides,
                                         const std::vector<SpecOverride>& new_overrides) {
  std::map<std::string, std::string> a, b;
  try {
    a = flatSpec(old_text, "old spec", old_overrides);
  } catch (const InputError&) { return {"(the recorded spec is not valid TOML)"}; }
  b = flatSpec(new_text, "new spec", new_overrides);
  std::vector<std::string> out;
  for (const auto& [k, v] : a)
    if (!b.count(k))
      out.push_back(k + " (removed)");
    else if (b[k] != v)
      out.push_back(k + " (" + v + " -> " + b[k] + ")");
  for (const auto& [k, v] : b)
    if (!a.count(k)) out.push_back(k + " (added)");
  return out;
}

void checkSampleDraws(const DatasetSpec& spec, const std::vector<std::int64_t>& indices) {
  std::set<std::string> profiles;
  for (const auto i : indices) {
    const ResolvedSample r = resolveSample(spec, i);
    try {
      const Scenario sc = readTomlParameters(*r.table, spec.file);
      for (const auto& kind : spec.labels == "kind" ? sc.growth->kinds() : std::vector<std::string>{})
        if (std::find(spec.kinds.begin(), spec.kinds.end(), kind) == spec.kinds.end()) {
          std::string list;
          for (const auto& k : spec.kinds) list += (list.empty() ? "" : ", ") + k;
          throw InputError(spec.file, spec.labels_line,
                           "the sample grows a tree of kind '" + kind + "', which has no label: kinds = [" + list + "]; add it to [dataset] kinds");
        }
      if (profiles.insert(r.profile).second) sampleProfile(spec, r.profile);
    } catch (const InputError& e) {
      throw InputError("", 0,
                       std::string(e.what()) + " (sample " + std::to_string(i) + ", " + r.id + "; see `angiosynth dataset describe " + spec.file +
                           " --index " + std::to_string(i) + "`)");
    }
  }
}

}  // namespace angiosynth
