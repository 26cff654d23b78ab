#include "config/common_params.hpp"

#include <sstream>

#include "angiosynth/templates.hpp"
#include "config/image_settings.hpp"
#include "config/mesh_settings.hpp"
#include "config/sample_settings.hpp"

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

std::string parameterTemplate(const GrowthMethod& method, const std::string& stem, std::string& data_file, std::string& data_content) {
  data_file.clear();
  data_content.clear();
  std::string text = exampleTemplate(method.name);
  if (std::string(method.name) == "vascusynth") {
    // The shipped example names a map of the source tree; the template brings its own: uniform
    // demand in a 100³ box.
    data_file = stem + "_demand.txt";
    data_content = "100 100 100\n0 0 0 100 100 100\n1\n";
    const std::string from = "\"../demand_maps/vascusynth_rods_100.txt\"";
    text.replace(text.find(from), from.size(), "\"" + data_file + "\"");
  }
  std::ostringstream o;
  o << text << "\n# Every key, at its default (uncomment to change; `angiosynth params " << method.name << "` explains them).\n";
  const auto block = [&](const std::vector<MethodParam>& ps) {
    std::string table = "-";
    for (const auto& p : ps) {
      if (!*p.table) continue;  // top-level keys (seed) stand at the top of the example itself
      if (table != p.table) {
        table = p.table;
        o << "#\n# [" << table << "]\n";
      }
      o << "# " << p.key << " = " << (p.fallback ? p.fallback : "(required)") << "   # " << p.meaning;
      if (*p.unit) o << " (" << p.unit << ')';
      o << '\n';
    }
  };
  block(method.params);
  block(commonParams());
  return o.str();
}

}  // namespace angiosynth
