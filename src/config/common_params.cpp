#include "config/common_params.hpp"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <map>
#include <optional>
#include <sstream>

#include <toml++/toml.h>

#include "angiosynth/templates.hpp"
#include "config/image_settings.hpp"
#include "config/mesh_settings.hpp"
#include "config/sample_settings.hpp"
#include "config/scenario.hpp"

namespace angiosynth {

const std::vector<MethodParam>& commonParams() {
  // The declared settings (config/*_settings.cpp), in the order of the reference.
  static const std::vector<SettingRow> rows = [] {
    std::vector<SettingRow> out;
    for (const auto& list : {referenceRows(curveSettings()), referenceRows(imageSettings()), referenceRows(labelSettings()),
                             referenceRows(outputSettings()), referenceRows(meshSettings())})
      out.insert(out.end(), list.begin(), list.end());
    return out;
  }();
  static const std::vector<MethodParam> all = [] {
    std::vector<MethodParam> out{
        {"", "seed", "integer ≥ 0", "fresh, recorded in sample.json", "the random seed: same seed and parameters, same bytes"}};
    for (const auto& r : rows) out.push_back({r.table.c_str(), r.key.c_str(), r.unit.c_str(), r.fallback.c_str(), r.meaning.c_str()});
    return out;
  }();
  return all;
}

namespace {

void line(std::ostream& o, const MethodParam& p) {
  o << "  ";
  if (*p.table) o << '[' << p.table << "] ";
  o << p.key;
  if (*p.unit) o << " (" << p.unit << ")";
  o << ": " << p.meaning << "; ";
  if (p.fallback)
    o << "default " << p.fallback << '\n';
  else
    o << "required\n";
}

}  // namespace

std::string parameterReference(const GrowthMethod* method) {
  std::ostringstream o;
  o << "Keys of every parameter file (quantities are strings \"<number> <unit>\"; unknown keys are errors):\n";
  for (const auto& p : commonParams()) line(o, p);
  for (const auto* m : growthMethods()) {
    if (method && method != m) continue;
    o << "\n[tree] method = \"" << m->name << "\": " << m->summary << ".\n";
    for (const auto& p : m->params) line(o, p);
  }
  return o.str();
}

namespace {

// A declared default as a TOML value, when it is one: a literal (20, 1e-6, true, ["stl"]), a
// quantity ("0.0036 Pa*s") or a word ("sphere"). Defaults that are rules ("the top (+y)") have none.
std::optional<std::string> defaultLiteral(const MethodParam& p) {
  if (!p.fallback) return std::nullopt;
  const std::string f = p.fallback;
  try {
    (void)toml::parse("k = " + f);
    return f;
  } catch (const toml::parse_error&) {}
  const auto space = f.find(' ');
  char* end = nullptr;
  if (space != std::string::npos && f.find(' ', space + 1) == std::string::npos && space > 0) {
    (void)std::strtod(f.c_str(), &end);
    if (end == f.c_str() + space) return "\"" + f + "\"";  // a quantity
  }
  if (!f.empty() && std::all_of(f.begin(), f.end(), [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }))
    return "\"" + f + "\"";
  return std::nullopt;
}

struct TemplateLine {
  const MethodParam* param;
  std::optional<std::string> value;  // uncommentable as `key = value`; else described only
};

std::string commentedLine(const TemplateLine& l, bool dotted) {
  const MethodParam& p = *l.param;
  std::string unit = *p.unit ? std::string(" (") + p.unit + ")" : "";
  if (l.value) return "# " + (dotted ? std::string(p.table) + "." : "") + p.key + " = " + *l.value + "   # " + p.meaning + unit + "\n";
  return std::string("#   ") + (dotted ? std::string(p.table) + "." : "") + p.key + ": " +
         (p.fallback ? "default " + std::string(p.fallback) : "required") + "; " + p.meaning + unit + "\n";
}

// The example's text cut at its table headers: the part before the first, then each table's.
struct ExampleSection {
  std::string table;  // "" for the part before the first header
  bool array = false;
  std::string text;
};

std::vector<ExampleSection> sections(const std::string& text) {
  std::vector<ExampleSection> out{{"", false, ""}};
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    const auto first = line.find_first_not_of(" \t");
    if (first != std::string::npos && line[first] == '[') {
      const bool array = line.compare(first, 2, "[[") == 0;
      const auto open = first + (array ? 2 : 1), close = line.find(']', open);
      if (close != std::string::npos) out.push_back({line.substr(open, close - open), array, ""});
    }
    out.back().text += line + "\n";
  }
  return out;
}

}  // namespace

std::string parameterTemplate(const GrowthMethod& method, const std::filesystem::path& file, std::string& data_file, std::string& data_content) {
  data_file.clear();
  data_content.clear();
  std::string text = exampleTemplate(method.name);
  if (std::string(method.name) == "vascusynth") {
    // The shipped example names a map of the source tree; the template brings its own: uniform
    // demand in a 100³ box.
    data_file = file.stem().string() + "_demand.txt";
    data_content = "100 100 100\n0 0 0 100 100 100\n1\n";
    const std::string from = "\"../demand_maps/vascusynth_rods_100.txt\"";
    text.replace(text.find(from), from.size(), "\"" + data_file + "\"");
  }
  const auto example = toml::parse(text);
  const auto parts = sections(text);
  // Every key the example leaves at its default, by table in the order of the reference.
  std::vector<std::string> order;
  std::map<std::string, std::vector<TemplateLine>> lines;
  for (const auto* list : {&method.params, &commonParams()})
    for (const auto& p : *list) {
      if (!*p.table) continue;  // top-level keys (seed) stand at the top of the example itself
      const auto* node = example.at_path(p.table).node();
      if (const auto* arr = node ? node->as_array() : nullptr; arr && !arr->empty()) node = arr->get(0);
      if (node && node->is_table() && node->as_table()->contains(p.key)) continue;
      if (!lines.count(p.table)) order.push_back(p.table);
      lines[p.table].push_back({&p, defaultLiteral(p)});
    }
  const auto inExample = [&](const std::string& table) {
    return std::any_of(parts.begin(), parts.end(), [&](const ExampleSection& s) { return s.table == table; });
  };
  const auto assemble = [&] {
    std::string o = parts[0].text;
    while (o.size() > 1 && o[o.size() - 1] == '\n' && o[o.size() - 2] == '\n') o.pop_back();
    o += "\n\n# Every other key at its default: uncomment a `key = value` line to change it; the `key:` lines\n"
         "# describe keys whose default is a rule or that other keys exclude (`angiosynth params " +
         std::string(method.name) + "`).\n";
    // Tables the example does not have, as dotted keys here, before its first table: a line
    // uncommented alone lands in its own table.
    for (const auto& table : order) {
      if (inExample(table) || table.find('.') != std::string::npos) continue;
      o += "#\n";
      for (const auto& l : lines[table]) o += commentedLine(l, true);
    }
    for (std::size_t k = 1; k < parts.size(); ++k) {
      o += parts[k].text;
      const bool last_of_table =
          std::none_of(parts.begin() + std::ptrdiff_t(k) + 1, parts.end(), [&](const ExampleSection& s) { return s.table == parts[k].table; });
      if (last_of_table && lines.count(parts[k].table)) {
        while (o.size() > 1 && o[o.size() - 1] == '\n' && o[o.size() - 2] == '\n') o.pop_back();
        for (const auto& l : lines[parts[k].table]) o += commentedLine(l, false);
        o += "\n";
      }
    }
    // Sub-tables (one per inlet, per stage) the example does not have: their header comes with them.
    for (const auto& table : order) {
      if (inExample(table) || table.find('.') == std::string::npos) continue;
      while (o.size() > 1 && o[o.size() - 1] == '\n' && o[o.size() - 2] == '\n') o.pop_back();
      o += "\n# [[" + table + "]]   (one table each: uncomment the header with its keys)\n";
      for (auto l : lines[table]) o += commentedLine({l.param, std::nullopt}, false);
    }
    return o;
  };
  // Each `key = value` line is one the reader takes when it alone is uncommented; any other is
  // described instead (a key another one excludes, a value the example's own keys rule out).
  const std::string base = assemble();
  for (auto& [table, list] : lines)
    for (auto& l : list) {
      if (!l.value) continue;
      const bool dotted = !inExample(table) && table.find('.') == std::string::npos;
      const std::string commented = commentedLine(l, dotted);
      const auto at = base.find(commented);
      bool accepted = false;
      if (at != std::string::npos) {
        std::string trial = base;
        trial.replace(at, commented.size(), commented.substr(2));
        try {
          (void)readTomlParameters(toml::parse(trial, file.string()), file);
          accepted = true;
        } catch (const std::exception&) {}
      }
      if (!accepted) l.value.reset();
    }
  return assemble();
}

}  // namespace angiosynth
