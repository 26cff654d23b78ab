#include "score/dataset_scores.hpp"

#include "core/format.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include "core/error.hpp"
#include "score/measures.hpp"
#include "score/metric.hpp"

namespace angiosynth {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

// Scores to six significant digits (the JSON keeps every digit): ratios of voxel counts, read by
// people and spreadsheets.
std::string number(double v) { return show(v, 6); }

Json readJson(const fs::path& f) {
  std::ifstream in(f);
  const Json j = Json::parse(in, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded() || !j.is_object()) throw InputError(f.string(), 0, "is not a JSON object angiosynth wrote");
  return j;
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

const char* datasetTruthName(DatasetTruth t) { return t == DatasetTruth::Training ? "training" : "exact"; }

TruthFiles datasetCaseTruth(const fs::path& ds, const std::string& id, DatasetTruth which) {
  const fs::path g = ds / "groundtruth" / id;
  if (!fs::is_regular_file(ds / "groundtruth" / (id + ".json")))
    throw InputError(ds.string(), 0, "has no case " + id + " (groundtruth/" + id + ".json); allowed: the case ids of its groundtruth/");
  const Json meta = readJson(ds / "groundtruth" / (id + ".json"));
  const Json& sample = meta.contains("sample") ? meta["sample"] : Json::object();
  const Json spec = fs::is_regular_file(ds / "spec.json") ? readJson(ds / "spec.json") : Json::object();
  const std::string policy = spec.contains("label_policy") && spec["label_policy"].is_string() ? spec["label_policy"].get<std::string>() : "binary";
  const bool by_kind = meta.contains("label_values") && meta["label_values"].is_object() && !meta["label_values"].contains("vessel");
  // The profile's own labels where it warps them (role_<profile>), else the clean ones.
  std::string suffix;
  if (sample.contains("degradation") && sample["degradation"].is_object())
    for (const auto& [name, rec] : sample["degradation"].items())
      if (fs::exists(g / ("centerline_" + name + ".nii.gz"))) suffix = "_" + name;
  const auto file = [&](const std::string& stem, const char* ext) { return g / (stem + suffix + ext); };
  const fs::path label = ds / "labelsTr" / (id + ".nii.gz");
  TruthFiles t;
  t.centerline = file("centerline", ".nii.gz"), t.radius = file("radius", ".nii.gz");
  t.legend = classLegend(sample);
  // The soft policy's label is the partial volume itself: its hard form is the exact mask.
  if (which == DatasetTruth::Training && policy != "soft") {
    t.mask = label;
    t.name = (ds.filename() / "labelsTr" / (id + ".nii.gz")).string();
    t.what = "the training label (labelsTr; label policy " + policy + (by_kind ? ", labelled by kind" : "") + ")";
    if (meta.contains("label_values") && meta["label_values"].contains("ignore")) {
      t.ignore_value = meta["label_values"]["ignore"].get<int>();
      t.what += "; its ignore label (" + std::to_string(*t.ignore_value) + ") counts neither way";
    }
  } else {
    t.mask = file("mask", ".nii.gz");
    t.name = (ds.filename() / "groundtruth" / id).string();
    t.what = "the exact mask (partial volume >= 0.5 or crossed by a centreline)";
    if (!fs::is_regular_file(t.mask)) {
      // Moved into labelsTr: the dataset's labels are the mask (binary labels).
      const bool binary = policy == "binary" && !by_kind;
      if (!binary)
        throw InputError(g.string(), 0,
                         "no mask of the case's image: this dataset's labelsTr holds labels by kind or by a label policy, "
                         "not the mask; allowed: datasets made by this version (they keep the mask in groundtruth/)");
      t.mask = label;
    }
  }
  for (const auto* f : {&t.mask, &t.centerline, &t.radius})
    if (!fs::is_regular_file(*f)) throw InputError(f->string(), 0, "missing: the dataset is incomplete (run `angiosynth dataset verify`)");
  if (fs::is_regular_file(file("edges", ".csv")) && fs::is_regular_file(file("nodes", ".csv"))) t.edges = file("edges", ".csv");
  if (fs::is_regular_file(file("keypoints", ".csv"))) t.keypoints = file("keypoints", ".csv");
  // The distractor label of the case's image (its profile's).
  if (sample.contains("degradation") && sample["degradation"].is_object())
    for (const auto& [name, rec] : sample["degradation"].items())
      if (fs::is_regular_file(g / ("distractors_" + name + ".nii.gz"))) t.distractors = g / ("distractors_" + name + ".nii.gz");
  // Kinds: the classes volume where the case keeps it, else labelsTr when it holds the classes.
  if (fs::is_regular_file(file("classes", ".nii.gz")))
    t.classes = file("classes", ".nii.gz");
  else if (by_kind)
    t.classes = label;
  return t;
}

namespace {

std::vector<std::string> datasetCases(const fs::path& ds) {
  std::vector<std::string> ids;
  for (const auto& e : fs::directory_iterator(ds / "groundtruth")) {
    const auto name = e.path().filename().string();
    if (e.is_regular_file() && name.ends_with(".json")) ids.push_back(name.substr(0, name.size() - 5));
  }
  std::sort(ids.begin(), ids.end());
  return ids;
}

// nnU-Net's splits_final.json: a list of folds, each {"train": [ids], "val": [ids]}.
std::vector<std::string> foldCases(const fs::path& splits, int fold) {
  std::ifstream in(splits);
  const Json s = Json::parse(in, nullptr, /*allow_exceptions=*/false);
  if (s.is_discarded() || !s.is_array() || s.empty())
    throw InputError(splits.string(), 0, "is not nnU-Net's splits_final.json (a list of {\"train\": [...], \"val\": [...]})");
  if (fold < 0 || fold >= int(s.size()))
    throw InputError(splits.string(), 0, "has folds 0 to " + std::to_string(s.size() - 1) + "; --fold " + std::to_string(fold) + " is not one");
  const Json& f = s[std::size_t(fold)];
  if (!f.is_object() || !f.contains("val") || !f["val"].is_array())
    throw InputError(splits.string(), 0, "fold " + std::to_string(fold) + " has no \"val\" list of case ids");
  std::vector<std::string> ids;
  for (const auto& id : f["val"])
    if (id.is_string()) ids.push_back(id.get<std::string>());
  return ids;
}

}  // namespace

DatasetScores scoreDataset(const fs::path& ds, const fs::path& predictions, const ScoreOptions& opt, const DatasetScoreOptions& select,
                           const ProgressFn& progress) {
  if (!fs::is_regular_file(ds / "dataset.json") || !fs::is_directory(ds / "groundtruth"))
    throw InputError(ds.string(), 0, "is not a dataset angiosynth made (no dataset.json or groundtruth/)");
  if (!fs::is_directory(predictions)) throw InputError(predictions.string(), 0, "is not a directory of predictions (<case>.nii.gz)");
  const std::vector<std::string> all = datasetCases(ds);
  if (all.empty()) throw InputError(ds.string(), 0, "holds no case (groundtruth/<case>.json)");
  std::vector<std::string> ids = select.cases;
  std::string selection = "every case with a prediction";
  if (!select.splits.empty()) {
    ids = foldCases(select.splits, select.fold);
    selection = "the validation cases of fold " + std::to_string(select.fold) + " of " + select.splits.string();
  } else if (!ids.empty()) {
    selection = "the cases listed";
  } else {
    ids = all;
  }
  for (const auto& id : ids)
    if (!std::binary_search(all.begin(), all.end(), id))
      throw InputError(ds.string(), 0, "has no case " + id + "; allowed: its case ids (groundtruth/<case>.json), e.g. " + all.front());
  DatasetScores out;
  for (const auto& id : ids) (fs::is_regular_file(predictions / (id + ".nii.gz")) ? out.scored : out.missing).push_back(id);
  if (out.scored.empty())
    throw InputError(predictions.string(), 0,
                     "holds no prediction for " + selection + " (nnU-Net naming: <case>.nii.gz, e.g. " + ids.front() + ".nii.gz)");
  // Predictions that name no case of the dataset: a misnamed file is otherwise silently left out.
  Json unmatched = Json::array();
  for (const auto& e : fs::directory_iterator(predictions)) {
    const auto name = e.path().filename().string();
    if (name.ends_with(".nii.gz") && !std::binary_search(all.begin(), all.end(), name.substr(0, name.size() - 7))) unmatched.push_back(name);
  }
  const auto columns = headlineColumns();
  Json cases = Json::array();
  out.csv = scoreCsvHeader();
  std::vector<std::vector<double>> values(columns.size());
  std::vector<std::vector<Json>> blocks(scoreMetrics().size());
  std::int64_t done = 0;
  Json conventions, definitions, truth_is;
  for (const auto& id : out.scored) {
    const CaseScores scores = scoreCase(predictions / (id + ".nii.gz"), datasetCaseTruth(ds, id, select.truth), opt);
    out.csv += scoreCsvRow(id, scores);
    for (std::size_t k = 0; k < columns.size(); ++k)
      if (const auto v = scores.headline(columns[k])) values[k].push_back(*v);
    for (std::size_t m = 0; m < scoreMetrics().size(); ++m) {
      Json b;
      for (const auto& block : scores.blocks)
        if (block.metric == scoreMetrics()[m]) b = block.detail;
      blocks[m].push_back(std::move(b));
    }
    const Json j = scores.toJson();
    conventions = j["conventions"];
    definitions = j["definitions"];
    truth_is = j["truth_is"];
    Json c{{"case", id}};
    for (const auto& [k, v] : j.items())
      if (k != "definitions" && k != "conventions" && k != "truth_is") c[k] = v;
    cases.push_back(c);
    if (progress) progress(++done, std::int64_t(out.scored.size()));
  }
  Json sum = Json::object();
  for (std::size_t k = 0; k < columns.size(); ++k) sum[columns[k]] = summaryOf(values[k]);
  for (const char* stat : {"mean", "median", "sd"}) {
    std::string row = stat;
    for (const auto& column : columns) {
      row += ',';
      const Json& s = sum[column];
      if (s.contains(stat) && s[stat].is_number()) row += number(s[stat].get<double>());
    }
    out.csv += row + '\n';
  }
  Json aggregates = Json::object();
  for (std::size_t m = 0; m < scoreMetrics().size(); ++m) {
    const ScoreMetric* metric = scoreMetrics()[m];
    if (!metric->aggregate) continue;
    std::vector<const Json*> b;
    for (const auto& x : blocks[m]) b.push_back(x.is_null() ? nullptr : &x);
    if (Json a = metric->aggregate(b); !a.is_null()) aggregates[metric->key] = a;
  }
  if (aggregates.contains("per_class")) {
    const char* keys[] = {"dice", "cldice", "b0_error", "hd95_mm", "recall", "centreline_recall"};
    out.class_csv = "class,cases_present";
    for (const char* k : keys) (((out.class_csv += ',') += k) += "_mean,") += std::string(k) + "_sd";
    out.class_csv += '\n';
    const auto row = [&](const std::string& name, const Json& k, const Json& present) {
      std::string r = csvField(name) + ',' + (present.is_number() ? std::to_string(present.get<std::int64_t>()) : std::string());
      for (const char* key : keys)
        for (const char* stat : {"mean", "sd"}) {
          r += ',';
          if (k.contains(key) && k[key].contains(stat) && k[key][stat].is_number()) r += number(k[key][stat].get<double>());
        }
      return r + '\n';
    };
    for (const auto& [name, k] : aggregates["per_class"]["classes"].items()) out.class_csv += row(name, k, k["cases_present"]);
    out.class_csv += row("class average", aggregates["per_class"]["class_average"], Json(out.scored.size()));
  }
  out.results = Json{{"dataset", ds.string()},
                     {"predictions", predictions.string()},
                     {"truth", datasetTruthName(select.truth)},
                     {"truth_is", truth_is},
                     {"selection", selection},
                     {"cases", out.scored.size()},
                     {"missing_predictions", out.missing},
                     {"unmatched_predictions", unmatched},
                     {"summary", sum},
                     {"summary_definition", "per headline metric over the cases where it is defined: mean, median, sd (n - 1), min, max"},
                     {"aggregates", aggregates},
                     {"conventions", conventions},
                     {"definitions", definitions},
                     {"per_case", cases}};
  return out;
}

}  // namespace angiosynth
