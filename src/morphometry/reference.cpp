#include "morphometry/reference.hpp"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>

#include "angiosynth/morphometry_references.hpp"
#include "core/error.hpp"
#include "core/format.hpp"
#include "core/quantity_json.hpp"
#include "files/toml_file.hpp"
#include "settings/toml_reader.hpp"

namespace angiosynth {
namespace fs = std::filesystem;
namespace {

const double kNaN = std::numeric_limits<double>::quiet_NaN();
const char* const kHorton[] = {"horton_branching", "horton_diameter", "horton_length"};

bool isVesselStatistic(const std::string& name) {
  for (const auto& [key, value] : vesselStatistics())
    if (key == name) return true;
  return false;
}

bool isBifurcationStatistic(const std::string& name) {
  for (const auto& [key, value] : bifurcationStatistics())
    if (key == name) return true;
  return false;
}

std::string knownStatistics() {
  std::string list;
  for (const auto& [key, value] : vesselStatistics()) list += (list.empty() ? "" : ", ") + key;
  for (const auto& [key, value] : bifurcationStatistics()) list += ", " + key;
  for (const char* h : kHorton) list += std::string(", ") + h;
  return list;
}

double toNumber(const toml::node& n) {
  if (const auto v = n.value<double>()) return *v;
  return kNaN;
}

// [lower, upper] of a band given as [number, number or inf].
void readBand(const TomlReader& r, const toml::node* n, ReferenceStatistic& s) {
  const auto* a = n->as_array();
  if (!a || a->size() != 2) throw InputError(r.file(), r.lineOf(n), "band_mm must be [lower, upper] in mm (upper may be inf)");
  s.lower_mm = toNumber(*a->get(0));
  s.upper_mm = toNumber(*a->get(1));
  if (!(s.lower_mm >= 0) || !(s.upper_mm > s.lower_mm))
    throw InputError(r.file(), r.lineOf(n), "band_mm [" + show(s.lower_mm) + ", " + show(s.upper_mm) + "]: allowed: 0 <= lower < upper (mm)");
}

ReferenceStatistic readStatistic(const TomlReader& r, const toml::table& t) {
  r.checkKeys(t, {"name", "mean", "median", "location", "sd", "scale", "scale_note", "count", "samples", "band_mm", "source"}, "[[statistic]]");
  ReferenceStatistic s;
  s.name = r.string(t, "statistic", "name");
  if (!isVesselStatistic(s.name) && !isBifurcationStatistic(s.name) && std::find(std::begin(kHorton), std::end(kHorton), s.name) == std::end(kHorton))
    throw InputError(r.file(), r.lineOf(t.get("name")), "statistic '" + s.name + "' is not one stats measures; allowed: " + knownStatistics());
  if (const auto* b = t.get("band_mm")) readBand(r, b, s);
  if (t.get("source")) s.source = r.string(t, "statistic", "source");
  if (t.get("count")) s.count = r.integer(t, "statistic", "count");
  if (const auto* n = t.get("samples")) {
    if (t.get("mean") || t.get("sd") || t.get("scale"))
      throw InputError(r.file(), r.lineOf(n), "give samples or a summary (mean with sd or scale), not both");
    s.samples = r.numbers(n, "samples", 0);
    if (s.samples.size() < 2) throw InputError(r.file(), r.lineOf(n), "samples holds fewer than 2 values; allowed: 2 or more numbers");
    s.count = std::int64_t(s.samples.size());
    return s;
  }
  s.mean = r.number(t, "statistic", "mean");
  if (t.get("location")) {
    const auto where = r.string(t, "statistic", "location");
    if (where != "mean" && where != "median")
      throw InputError(r.file(), r.lineOf(t.get("location")), "location '" + where + "' is not allowed; allowed: mean, median");
    s.median = where == "median";
  }
  if (t.get("sd") && t.get("scale")) throw InputError(r.file(), r.lineOf(t.get("scale")), "give sd or scale, not both");
  if (t.get("sd")) {
    s.spread = r.number(t, "statistic", "sd");
    s.spread_note = "sd";
  } else if (t.get("scale")) {
    s.spread = r.number(t, "statistic", "scale");
    if (!t.get("scale_note"))
      throw InputError(r.file(), r.lineOf(t.get("scale")), "a scale needs scale_note: why this spread, since the source gives none");
    s.spread_note = r.string(t, "statistic", "scale_note");
  } else {
    throw InputError(r.file(), r.lineOf(&t), "statistic '" + s.name + "' needs samples, or mean with sd (or with scale and scale_note)");
  }
  if (!(s.spread > 0) || !std::isfinite(s.spread))
    throw InputError(r.file(), r.lineOf(t.get(t.get("sd") ? "sd" : "scale")), "the spread must be a number > 0");
  if (!std::isfinite(s.mean)) throw InputError(r.file(), r.lineOf(t.get("mean")), "mean must be a finite number");
  return s;
}

void readStrahler(const TomlReader& r, const toml::table& t, MorphometryReference& ref) {
  r.checkKeys(t, {"definition", "ordering", "source", "orders", "rows"}, "[strahler]");
  const std::string ordering = r.string(t, "strahler", "ordering");
  if (ordering != "diameter" && ordering != "topological")
    throw InputError(r.file(), r.lineOf(t.get("ordering")), "ordering '" + ordering + "' is not allowed; allowed: diameter, topological");
  ref.diameter_defined = ordering == "diameter";
  if (t.get("definition")) ref.strahler_definition = r.string(t, "strahler", "definition");
  if (t.get("source")) ref.strahler_source = r.string(t, "strahler", "source");
  const auto orders = r.numbers(r.need(t, "strahler", "orders"), "orders", 2);
  ref.ratio_from = int(orders[0]);
  ref.ratio_to = int(orders[1]);
  const auto* rows = r.need(t, "strahler", "rows")->as_array();
  if (!rows || rows->empty()) throw InputError(r.file(), r.lineOf(t.get("rows")), "rows must be an array of [order, D, sd D, L, sd L, elements]");
  for (const auto& row : *rows) {
    const auto* a = row.as_array();
    if (!a || a->size() != 6)
      throw InputError(r.file(), r.lineOf(&row),
                       "a row must hold [order, diameter µm, its sd, element length mm, its sd, elements in the tree] (nan: not given)");
    StrahlerReferenceRow x;
    x.order = int(toNumber(*a->get(0)));
    x.diameter_mm = toNumber(*a->get(1)) / 1000;
    x.diameter_sd_mm = toNumber(*a->get(2)) / 1000;
    x.length_mm = toNumber(*a->get(3));
    x.length_sd_mm = toNumber(*a->get(4));
    x.elements = toNumber(*a->get(5));
    if (!ref.strahler.empty() && x.order != ref.strahler.back().order + 1)
      throw InputError(r.file(), r.lineOf(&row), "orders must follow one another from the first row (order " + std::to_string(x.order) + ")");
    ref.strahler.push_back(x);
  }
  if (ref.ratio_from < ref.strahler.front().order || ref.ratio_to > ref.strahler.back().order || ref.ratio_to - ref.ratio_from < 2)
    throw InputError(r.file(), r.lineOf(t.get("orders")), "orders [from, to] must lie within the rows' orders and span 3 orders at least");
}

MorphometryReference parseReference(const toml::table& root, const std::string& file) {
  const TomlReader r(root, file);
  r.checkKeys(root, {"reference", "strahler", "statistic"}, "the reference file");
  const auto& info = r.table("reference", {"name", "title", "citation", "source", "species", "organ", "vessels", "method", "group"});
  MorphometryReference ref;
  ref.file = file;
  ref.name = r.string(info, "reference", "name");
  ref.title = r.string(info, "reference", "title");
  ref.citation = r.string(info, "reference", "citation");
  for (auto [key, field] : {std::pair{"source", &ref.source}, std::pair{"species", &ref.species}, std::pair{"organ", &ref.organ},
                            std::pair{"vessels", &ref.vessels}, std::pair{"method", &ref.method}, std::pair{"group", &ref.group}})
    if (info.get(key)) *field = r.string(info, "reference", key);
  if (const auto* s = root.get("strahler")) {
    if (!s->is_table()) throw InputError(file, r.lineOf(s), "[strahler] must be a table");
    readStrahler(r, *s->as_table(), ref);
  }
  if (const auto* list = root.get("statistic")) {
    const auto* a = list->as_array();
    if (!a || !a->is_array_of_tables()) throw InputError(file, r.lineOf(list), "statistic must be [[statistic]] tables");
    for (const auto& t : *a) ref.statistics.push_back(readStatistic(r, *t.as_table()));
  }
  if (ref.strahler.empty() && ref.statistics.empty()) throw InputError(file, 0, "the reference gives no [strahler] table and no [[statistic]]");
  return ref;
}

// Samples of every statistic a stats CSV holds a column of.
void readSampleColumns(const fs::path& csv, bool vessels, MorphometryReference& ref) {
  std::ifstream in(csv);
  if (!in)
    throw InputError(csv.string(), 0,
                     "no such file: a stats directory holds stats.json, vessels.csv and bifurcations.csv (angiosynth stats INPUT --out DIR)");
  std::string line;
  std::getline(in, line);
  const auto header = csvFieldsOf(line);
  std::vector<std::pair<std::size_t, ReferenceStatistic>> columns;
  for (std::size_t c = 0; c < header.size(); ++c)
    if (vessels ? isVesselStatistic(header[c]) : isBifurcationStatistic(header[c])) {
      ReferenceStatistic s;
      s.name = header[c];
      s.source = csv.filename().string();
      columns.emplace_back(c, s);
    }
  int line_no = 1;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.empty()) continue;
    const auto f = csvFieldsOf(line);
    if (f.size() != header.size())
      throw InputError(csv.string(), line_no, std::to_string(f.size()) + " fields; allowed: " + std::to_string(header.size()) + ", as the header");
    for (auto& [c, s] : columns) {
      char* end = nullptr;
      const double v = std::strtod(f[c].c_str(), &end);
      if (!f[c].empty() && end == f[c].c_str() + f[c].size() && std::isfinite(v)) s.samples.push_back(v);
    }
  }
  for (auto& [c, s] : columns) {
    s.count = std::int64_t(s.samples.size());
    if (s.samples.size() >= 2) ref.statistics.push_back(std::move(s));
  }
}

MorphometryReference fromStatsDirectory(const fs::path& dir) {
  MorphometryReference ref;
  ref.file = dir.string();
  ref.name = dir.filename().empty() ? dir.parent_path().filename().string() : dir.filename().string();
  ref.title = "the tree measured in " + dir.string();
  ref.citation = "angiosynth stats";
  readSampleColumns(dir / "vessels.csv", true, ref);
  readSampleColumns(dir / "bifurcations.csv", false, ref);
  if (ref.statistics.empty()) throw InputError(dir.string(), 0, "the stats directory holds no samples (empty vessels.csv and bifurcations.csv)");
  return ref;
}

// Horton's ratio of a column of the reference's Strahler table over its orders, with the SD of
// the log ratios of successive orders (the spread a standardised difference needs).
struct LogRatio {
  double ratio = kNaN, log_sd = kNaN;
  std::int64_t orders = 0;
};

LogRatio hortonOfReference(const MorphometryReference& ref, double StrahlerReferenceRow::*field, bool falling) {
  std::vector<double> x, y, steps;
  const StrahlerReferenceRow* previous = nullptr;
  for (const auto& row : ref.strahler) {
    if (row.order < ref.ratio_from || row.order > ref.ratio_to || !(row.*field > 0)) {
      previous = nullptr;
      continue;
    }
    x.push_back(row.order);
    y.push_back(std::log(row.*field));
    if (previous) steps.push_back((falling ? -1 : 1) * (std::log(row.*field) - std::log(previous->*field)));
    previous = &row;
  }
  LogRatio out;
  out.orders = std::int64_t(x.size());
  out.ratio = std::exp((falling ? -1 : 1) * leastSquaresSlope(x, y));
  out.log_sd = summarise(steps).sd;
  if (steps.size() < 2) out.log_sd = kNaN;
  return out;
}

// The KS distance between two normal laws with one spread, |d| spreads apart.
double normalDistance(double d) { return std::erf(std::abs(d) / (2 * std::sqrt(2.0))); }

std::string bandText(double lo, double hi) {
  if (lo == 0 && !std::isfinite(hi)) return "";
  return show(lo) + "–" + (std::isfinite(hi) ? show(hi) : std::string("inf"));
}

}  // namespace

std::vector<std::string> shippedMorphometryReferences() {
  std::vector<std::string> names;
  for (const auto& [name, text] : shippedReferenceTexts()) names.push_back(name);
  return names;
}

MorphometryReference readMorphometryReference(const std::string& arg) {
  const fs::path p(arg);
  if (fs::is_directory(p)) return fromStatsDirectory(p);
  if (fs::exists(p)) return parseReference(parseTomlFile(p, "reference file"), p.string());
  for (const auto& [name, text] : shippedReferenceTexts())
    if (name == arg) {
      const std::string file = "data/morphometry/" + name + ".toml";
      try {
        return parseReference(toml::parse(text, file), file);
      } catch (const toml::parse_error& e) {
        throw InputError(file, static_cast<int>(e.source().begin.line), std::string("not valid TOML: ") + std::string(e.description()));
      }
    }
  std::string list;
  for (const auto& n : shippedMorphometryReferences()) list += (list.empty() ? "" : ", ") + n;
  throw InputError(arg, 0, "no such reference file, stats directory or shipped reference; shipped: " + list);
}

KsResult kolmogorovSmirnov(std::vector<double> a, std::vector<double> b) {
  const auto finite = [](double v) { return !std::isfinite(v); };
  a.erase(std::remove_if(a.begin(), a.end(), finite), a.end());
  b.erase(std::remove_if(b.begin(), b.end(), finite), b.end());
  KsResult r;
  if (a.empty() || b.empty()) return r;
  std::sort(a.begin(), a.end());
  std::sort(b.begin(), b.end());
  const double na = double(a.size()), nb = double(b.size());
  std::size_t i = 0, j = 0;
  double d = 0;
  while (i < a.size() && j < b.size()) {
    const double v = std::min(a[i], b[j]);
    while (i < a.size() && a[i] == v) ++i;  // ties step both empirical laws at once
    while (j < b.size() && b[j] == v) ++j;
    d = std::max(d, std::abs(double(i) / na - double(j) / nb));
  }
  r.d = d;
  const double en = std::sqrt(na * nb / (na + nb));
  const double lambda = (en + 0.12 + 0.11 / en) * d;
  if (lambda < 0.2) {
    r.p = 1;
    return r;
  }
  double sum = 0, sign = 1;
  for (int k = 1; k <= 100; ++k) {
    const double term = sign * 2 * std::exp(-2.0 * k * k * lambda * lambda);
    sum += term;
    if (std::abs(term) < 1e-12 * sum) break;
    sign = -sign;
  }
  r.p = std::clamp(sum, 0.0, 1.0);
  return r;
}

MorphometryComparison compareMorphometry(const Morphometry& m, const MorphometryReference& ref) {
  MorphometryComparison out;
  out.reference = ref.name;
  out.title = ref.title;
  out.citation = ref.citation;
  out.group = ref.group;
  const MorphometryGroup* group = nullptr;
  std::string names;
  for (const auto& g : m.groups) {
    if (g.name == ref.group) group = &g;
    names += (names.empty() ? "" : ", ") + g.name;
  }
  if (!group) throw InputError(ref.file, 0, "the tree has no group '" + ref.group + "' to compare; its groups: " + names);
  const std::set<std::int32_t> trees(group->trees.begin(), group->trees.end());
  const auto treeSamples = [&](const std::string& stat, double lo, double hi) {
    std::vector<double> v;
    for (const auto& [key, value] : vesselStatistics())
      if (key == stat)
        for (const auto& x : m.vessels)
          if (trees.count(x.tree) && x.radius_mm >= lo && x.radius_mm < hi) v.push_back(value(x));
    for (const auto& [key, value] : bifurcationStatistics())
      if (key == stat)
        for (const auto& x : m.bifurcations)
          if (trees.count(x.tree) && x.r_parent_mm >= lo && x.r_parent_mm < hi) v.push_back(value(x));
    v.erase(std::remove_if(v.begin(), v.end(), [](double x) { return !std::isfinite(x); }), v.end());
    return v;
  };
  const auto hortonOfTree = [&](const std::string& stat, bool by_diameter) {
    const HortonRatios h =
        by_diameter ? group->horton_by_diameter : HortonRatios{group->horton_branching, group->horton_length, group->horton_diameter};
    return stat == "horton_branching" ? h.branching : stat == "horton_diameter" ? h.diameter : h.length;
  };
  if (!ref.strahler.empty()) {
    const std::pair<const char*, LogRatio> ratios[] = {{"horton_branching", hortonOfReference(ref, &StrahlerReferenceRow::elements, true)},
                                                       {"horton_diameter", hortonOfReference(ref, &StrahlerReferenceRow::diameter_mm, false)},
                                                       {"horton_length", hortonOfReference(ref, &StrahlerReferenceRow::length_mm, false)}};
    for (const auto& [name, lr] : ratios) {
      if (!std::isfinite(lr.ratio) || !(lr.log_sd > 0)) continue;
      ComparisonRow row;
      row.statistic = name;
      row.test = "standardised (log)";
      row.reference = lr.ratio;
      row.reference_spread = lr.log_sd;
      row.reference_count = lr.orders;
      row.tree = hortonOfTree(name, ref.diameter_defined);
      row.tree_count = std::int64_t((ref.diameter_defined ? group->diameter_orders : group->strahler).size());
      row.source = ref.strahler_source + " (orders " + std::to_string(ref.ratio_from) + "–" + std::to_string(ref.ratio_to) + ", " +
                   (ref.diameter_defined ? "diameter-defined" : "topological") + ")";
      if (row.tree > 0 && std::isfinite(row.tree)) {
        row.statistic_value = (std::log(row.tree) - std::log(lr.ratio)) / lr.log_sd;
        row.distance = normalDistance(row.statistic_value);
      }
      out.rows.push_back(row);
    }
  }
  for (const auto& s : ref.statistics) {
    ComparisonRow row;
    row.statistic = s.name;
    row.lower_mm = s.lower_mm;
    row.upper_mm = s.upper_mm;
    row.source = s.source;
    row.reference_count = s.count;
    const bool horton = std::find(std::begin(kHorton), std::end(kHorton), s.name) != std::end(kHorton);
    if (horton) {
      row.test = "standardised";
      row.tree = hortonOfTree(s.name, false);
      row.tree_count = std::int64_t(group->strahler.size());
      row.reference = s.mean;
      row.reference_spread = s.spread;
      if (std::isfinite(row.tree)) {
        row.statistic_value = (row.tree - s.mean) / s.spread;
        row.distance = normalDistance(row.statistic_value);
      }
      out.rows.push_back(row);
      continue;
    }
    const auto mine = treeSamples(s.name, s.lower_mm, s.upper_mm);
    row.tree_count = std::int64_t(mine.size());
    if (!s.samples.empty()) {
      row.test = "ks";
      row.tree = summarise(mine).median;
      row.reference = summarise(s.samples).median;
      if (!mine.empty()) {
        const auto ks = kolmogorovSmirnov(mine, s.samples);
        row.statistic_value = row.distance = ks.d;
        row.p_value = ks.p;
      }
    } else {
      row.test = "standardised";
      const Summary sm = summarise(mine);
      row.tree = s.median ? sm.median : sm.mean;
      row.reference = s.mean;
      row.reference_spread = s.spread;
      if (!mine.empty()) {
        row.statistic_value = (row.tree - s.mean) / s.spread;
        row.distance = normalDistance(row.statistic_value);
      }
    }
    out.rows.push_back(row);
  }
  double sum = 0;
  for (const auto& r : out.rows)
    if (std::isfinite(r.distance)) sum += r.distance, ++out.compared;
  out.overall = out.compared ? sum / double(out.compared) : kNaN;
  return out;
}

nlohmann::ordered_json MorphometryComparison::toJson() const {
  using Json = nlohmann::ordered_json;
  Json list = Json::array();
  for (const auto& r : rows) {
    list.push_back(Json{{"statistic", r.statistic},
                        {"band_mm", rangeJson(r.lower_mm, r.upper_mm)},
                        {"test", r.test},
                        {"tree", numberOrNull(r.tree)},
                        {"reference", numberOrNull(r.reference)},
                        {"reference_spread", numberOrNull(r.reference_spread)},
                        {"tree_count", r.tree_count},
                        {"reference_count", r.reference_count},
                        {r.test == "ks" ? "ks_d" : "standardised_difference", numberOrNull(r.statistic_value)},
                        {"p_value", numberOrNull(r.p_value)},
                        {"distance", numberOrNull(r.distance)},
                        {"source", r.source}});
  }
  return Json{{"reference", reference},
              {"title", title},
              {"citation", citation},
              {"group", group},
              {"overall_distance", numberOrNull(overall)},
              {"statistics_compared", compared},
              {"statistics", list},
              {"definitions",
               {{"standardised_difference", "(tree − reference) / reference spread; Horton's ratios in log space"},
                {"ks_d", "two-sample Kolmogorov–Smirnov statistic against the reference's samples; p asymptotic (Stephens 1970)"},
                {"distance", "ks_d, or 2Φ(|d|/2) − 1: the KS distance of two normal laws |d| spreads apart; 0 = alike, 1 = apart"},
                {"overall_distance", "mean distance over the statistics the tree has values for"}}}};
}

std::string MorphometryComparison::table() const {
  std::ostringstream o;
  char line[512];
  std::snprintf(line, sizeof line, "compared with %s (%s), group %s: overall distance %.3f over %lld statistics\n", reference.c_str(),
                citation.c_str(), group.c_str(), overall, (long long)compared);
  o << line;
  std::snprintf(line, sizeof line, "  %-22s %-12s %11s %11s %10s %8s %9s\n", "statistic", "band (mm)", "tree", "reference", "spread", "d / D",
                "distance");
  o << line;
  for (const auto& r : rows) {
    std::snprintf(line, sizeof line, "  %-22s %-12s %11.4g %11.4g %10.3g %8.3g %9.3f%s\n", r.statistic.c_str(),
                  bandText(r.lower_mm, r.upper_mm).c_str(), r.tree, r.reference, r.reference_spread, r.statistic_value, r.distance,
                  r.test == "ks"              ? "  (KS)"
                  : std::isfinite(r.distance) ? ""
                                              : "  (none in the tree)");
    o << line;
  }
  return o.str();
}

}  // namespace angiosynth
