#include "score/dataset_scores.hpp"

#include "core/format.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include "core/error.hpp"

namespace angiosynth {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

// Scores to six significant digits (the JSON keeps every digit): ratios of voxel counts, read by
// people and spreadsheets.
std::string number(double v) { return show(v, 6); }

// RFC 4180: a field is quoted only when it holds a comma, a quote or a line break.
std::string csvField(const std::string& s) {
  if (s.find_first_of(",\"\r\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + '"';
}

Json readJson(const fs::path& f) {
  std::ifstream in(f);
  const Json j = Json::parse(in, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded() || !j.is_object()) throw InputError(f.string(), 0, "is not a JSON object angiosynth wrote");
  return j;
}

// n, mean, median, standard deviation (n − 1), min and max of the non-null values.
Json summary(std::vector<double> v) {
  Json s{{"cases", v.size()}};
  if (v.empty()) return s;
  std::sort(v.begin(), v.end());
  double sum = 0;
  for (double x : v) sum += x;
  const double mean = sum / double(v.size());
  double ss = 0;
  for (double x : v) ss += (x - mean) * (x - mean);
  const std::size_t n = v.size();
  s["mean"] = mean;
  s["median"] = n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
  s["sd"] = n > 1 ? Json(std::sqrt(ss / double(n - 1))) : Json(nullptr);
  s["min"] = v.front();
  s["max"] = v.back();
  return s;
}

}  // namespace

std::string scoreCsvHeader() {
  std::string h = "case";
  for (const auto& name : headlineColumns()) (h += ',') += name;
  return h + '\n';
}

std::string scoreCsvRow(const std::string& name, const CaseScores& scores) {
  std::string r = csvField(name);
  for (const auto& column : headlineColumns()) {
    r += ',';
    if (const auto v = scores.headline(column)) r += number(*v);
  }
  return r + '\n';
}

TruthFiles datasetCaseTruth(const fs::path& ds, const std::string& id) {
  const fs::path g = ds / "groundtruth" / id;
  const Json meta = readJson(ds / "groundtruth" / (id + ".json"));
  const Json& sample = meta.contains("sample") ? meta["sample"] : Json::object();
  // The profile's own labels where it warps them (role_<profile>), else the clean ones.
  std::string suffix;
  if (sample.contains("degradation") && sample["degradation"].is_object())
    for (const auto& [name, rec] : sample["degradation"].items())
      if (fs::exists(g / ("centerline_" + name + ".nii.gz"))) suffix = "_" + name;
  const auto file = [&](const std::string& stem, const char* ext) { return g / (stem + suffix + ext); };
  TruthFiles t;
  t.mask = file("mask", ".nii.gz"), t.centerline = file("centerline", ".nii.gz"), t.radius = file("radius", ".nii.gz");
  t.name = (ds.filename() / "groundtruth" / id).string();
  if (!fs::is_regular_file(t.mask)) {
    // Moved into labelsTr: the dataset's labels are the mask (binary labels).
    const Json spec = readJson(ds / "spec.json");
    const bool binary = !spec.contains("label_policy") && spec.contains("labels") && spec["labels"].contains("vessel");
    if (!binary)
      throw InputError(g.string(), 0,
                       "no mask of the case's image: this dataset's labelsTr holds labels by kind or by a label policy, "
                       "not the mask; allowed: datasets made by this version (they keep the mask in groundtruth/)");
    t.mask = ds / "labelsTr" / (id + ".nii.gz");
  }
  for (const auto* f : {&t.mask, &t.centerline, &t.radius})
    if (!fs::is_regular_file(*f)) throw InputError(f->string(), 0, "missing: the dataset is incomplete (run `angiosynth dataset verify`)");
  if (fs::is_regular_file(file("edges", ".csv")) && fs::is_regular_file(file("nodes", ".csv"))) t.edges = file("edges", ".csv");
  if (fs::is_regular_file(file("keypoints", ".csv"))) t.keypoints = file("keypoints", ".csv");
  // Kinds: the classes volume where the case keeps it, else labelsTr when it holds the classes.
  t.legend = classLegend(sample);
  if (fs::is_regular_file(file("classes", ".nii.gz")))
    t.classes = file("classes", ".nii.gz");
  else if (meta.contains("label_values") && !meta["label_values"].contains("vessel"))
    t.classes = ds / "labelsTr" / (id + ".nii.gz");
  return t;
}

Json scoreDataset(const fs::path& ds, const fs::path& predictions, const ScoreOptions& opt, const ProgressFn& progress, std::string& csv) {
  if (!fs::is_regular_file(ds / "dataset.json") || !fs::is_directory(ds / "groundtruth"))
    throw InputError(ds.string(), 0, "is not a dataset angiosynth made (no dataset.json or groundtruth/)");
  if (!fs::is_directory(predictions)) throw InputError(predictions.string(), 0, "is not a directory of predictions (<case>.nii.gz)");
  std::vector<std::string> ids;
  for (const auto& e : fs::directory_iterator(ds / "groundtruth")) {
    const auto name = e.path().filename().string();
    if (e.is_regular_file() && name.ends_with(".json")) ids.push_back(name.substr(0, name.size() - 5));
  }
  std::sort(ids.begin(), ids.end());
  if (ids.empty()) throw InputError(ds.string(), 0, "holds no case (groundtruth/<case>.json)");
  for (const auto& id : ids)
    if (!fs::is_regular_file(predictions / (id + ".nii.gz")))
      throw InputError((predictions / (id + ".nii.gz")).string(), 0, "missing: no prediction for case " + id + " (nnU-Net naming: <case>.nii.gz)");
  const auto columns = headlineColumns();
  Json cases = Json::array();
  csv = scoreCsvHeader();
  std::vector<std::vector<double>> values(columns.size());
  std::int64_t done = 0;
  Json conventions, definitions;
  for (const auto& id : ids) {
    const CaseScores scores = scoreCase(predictions / (id + ".nii.gz"), datasetCaseTruth(ds, id), opt);
    csv += scoreCsvRow(id, scores);
    for (std::size_t k = 0; k < columns.size(); ++k)
      if (const auto v = scores.headline(columns[k])) values[k].push_back(*v);
    const Json j = scores.toJson();
    conventions = j["conventions"];
    definitions = j["definitions"];
    Json c{{"case", id}};
    for (const auto& [k, v] : j.items())
      if (k != "definitions" && k != "conventions") c[k] = v;
    cases.push_back(c);
    if (progress) progress(++done, std::int64_t(ids.size()));
  }
  Json sum = Json::object();
  for (std::size_t k = 0; k < columns.size(); ++k) sum[columns[k]] = summary(values[k]);
  for (const char* stat : {"mean", "median", "sd"}) {
    std::string row = stat;
    for (const auto& column : columns) {
      row += ',';
      const Json& s = sum[column];
      if (s.contains(stat) && s[stat].is_number()) row += number(s[stat].get<double>());
    }
    csv += row + '\n';
  }
  return Json{{"dataset", ds.string()},
              {"predictions", predictions.string()},
              {"cases", cases.size()},
              {"summary", sum},
              {"summary_definition", "per headline metric over the cases where it is defined: mean, median, sd (n - 1), min, max"},
              {"conventions", conventions},
              {"definitions", definitions},
              {"per_case", cases}};
}

}  // namespace angiosynth
