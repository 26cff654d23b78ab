#include "score/case_scores.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>

#include "core/error.hpp"
#include "score/measures.hpp"
#include "score/metric.hpp"
#include "score/skeleton.hpp"

namespace angiosynth {
namespace {

using Json = nlohmann::ordered_json;

// Per voxel while scoring: five volumes of floats and bytes, two distance maps, the borders.
constexpr std::uint64_t kBytesPerVoxel = 4 * 4 + 2 * 8 + 4;

const char* conventionsText(ScoreConventions c) {
  return c == ScoreConventions::TopCoW
             ? "TopCoW: 26-neighbour borders; a surface distance 90 mm (the label scheme's bound) when one mask is empty; Dice, "
               "Jaccard and clDice 0 when both masks (or skeletons) are empty; a class present on one side only scores Dice 0"
             : "default: 6-neighbour borders; null for a surface distance when one mask is empty; Dice and Jaccard 1 when both are; "
               "clDice null when a skeleton is empty";
}

}  // namespace

std::string ScoreOptions::invalid() const {
  for (const auto* bins : {&bins_voxels, &bins_mm})
    for (std::size_t k = 0; k < bins->size(); ++k)
      if (!std::isfinite((*bins)[k]) || (*bins)[k] < 0 || (k > 0 && (*bins)[k] <= (*bins)[k - 1]))
        return "calibre bins must be finite, non-negative and increasing (lower edges)";
  if (bins_voxels.empty()) return "give at least one calibre bin in voxels";
  if (tolerance_mm && !(std::isfinite(*tolerance_mm) && *tolerance_mm > 0)) return "the NSD tolerance must be a positive length in mm";
  if (boundary_width_mm && !(std::isfinite(*boundary_width_mm) && *boundary_width_mm > 0))
    return "the Boundary IoU band width must be a positive length in mm";
  if (!(std::isfinite(grid_tolerance_voxels) && grid_tolerance_voxels >= 0)) return "the grid tolerance must be a non-negative number of voxels";
  return "";
}

namespace {

Volume<std::uint8_t> valueVoxels(const Volume<float>& v, std::optional<int> value) {
  Volume<std::uint8_t> out(v.grid);
  if (value)
    for (std::size_t i = 0; i < v.data.size(); ++i) out.data[i] = std::lround(v.data[i]) == *value;
  return out;
}

Volume<std::uint8_t> vesselVoxels(const Volume<float>& v, const Volume<std::uint8_t>& ignore) {
  Volume<std::uint8_t> out(v.grid);
  for (std::size_t i = 0; i < v.data.size(); ++i) out.data[i] = v.data[i] > 0 && !ignore.data[i];
  return out;
}

// A voxel value as a class (0 … 255).
std::uint8_t classOf(float v) { return std::uint8_t(std::clamp<long>(std::lround(v), 0, 255)); }

}  // namespace

ScoringCase::ScoringCase(const ScoreOptions& o, const TruthFiles& f, const NiftiVolume& pred, const NiftiVolume& t, const Volume<float>* centre,
                         const Volume<float>* rad)
    : options(o),
      files(f),
      prediction_file(pred),
      truth_file(t),
      ignore(valueVoxels(t.values, f.ignore_value)),
      prediction(vesselVoxels(pred.values, ignore)),
      truth(vesselVoxels(t.values, ignore)),
      centreline(centre),
      radius(rad),
      voxel_mm(smallestEdge(t.values.grid)),
      tolerance_mm(o.tolerance_mm ? *o.tolerance_mm : smallestEdge(t.values.grid)) {}

const Volume<std::uint8_t>& ScoringCase::predictionSkeleton() const {
  if (!prediction_skeleton_) prediction_skeleton_ = skeletonize(prediction);
  return *prediction_skeleton_;
}

const Volume<std::uint8_t>& ScoringCase::truthSkeleton() const {
  if (!truth_skeleton_) truth_skeleton_ = skeletonize(truth);
  return *truth_skeleton_;
}

const Volume<std::uint8_t>* ScoringCase::truthClasses() const {
  if (!classes_read_) {
    classes_read_ = true;
    const bool labelled_mask = std::any_of(truth_file.values.data.begin(), truth_file.values.data.end(),
                                           [&](float v) { return v > 1.5f && !(files.ignore_value && std::lround(v) == *files.ignore_value); });
    std::optional<NiftiVolume> own;
    const Volume<float>* values = nullptr;
    if (!files.classes.empty() && !labelled_mask) {
      own = readTruthVolume(files.classes, "the truth classes");
      values = &own->values;
    } else if (labelled_mask || !files.legend.empty() || options.scheme) {
      values = &truth_file.values;
    }
    if (values) {
      Volume<std::uint8_t> c(truth.grid);
      for (std::size_t i = 0; i < c.data.size(); ++i) c.data[i] = truth.data[i] ? classOf(values->data[i]) : 0;
      truth_classes_ = std::move(c);
    }
  }
  return truth_classes_ ? &*truth_classes_ : nullptr;
}

const Volume<std::uint8_t>& ScoringCase::predictionClasses() const {
  if (!prediction_classes_) {
    Volume<std::uint8_t> c(prediction.grid);
    for (std::size_t i = 0; i < c.data.size(); ++i) c.data[i] = prediction.data[i] ? classOf(prediction_file.values.data[i]) : 0;
    prediction_classes_ = std::move(c);
  }
  return *prediction_classes_;
}

bool ScoringCase::predictionLabelled() const {
  // Labels are whole numbers from 0 to 255: a probability map or an image of intensities (HU,
  // signal) as the prediction is binary.
  const auto& p = prediction_file.values.data;
  if (std::any_of(p.begin(), p.end(), [](float v) { return v != std::nearbyint(v) || v < 0 || v > 255; })) return false;
  if (std::any_of(p.begin(), p.end(), [](float v) { return v > 1.5f; })) return true;
  const auto* t = truthClasses();
  return t && std::none_of(t->data.begin(), t->data.end(), [](std::uint8_t v) { return v > 1; });
}

std::string ScoringCase::className(int value) const {
  if (const auto it = files.legend.find(value); it != files.legend.end()) return it->second;
  if (options.scheme)
    if (const auto it = options.scheme->labels.find(value); it != options.scheme->labels.end()) return it->second;
  return "label " + std::to_string(value);
}

NiftiVolume ScoringCase::readTruthVolume(const std::filesystem::path& file, const char* what) const {
  NiftiVolume v = readNiftiVolume(file, options.memory_limit, kBytesPerVoxel, what);
  checkSameGrid(v, truth_file, file.string(), files.mask.string(), options.grid_tolerance_voxels);
  return v;
}

std::optional<double> CaseScores::headline(const std::string& column) const {
  for (const auto& b : blocks)
    for (std::size_t k = 0; k < b.metric->headline.size(); ++k)
      if (column == b.metric->headline[k].column) return b.headline[k];
  return std::nullopt;
}

Json CaseScores::toJson() const {
  Json j;
  j["prediction"] = prediction;
  j["truth"] = truth;
  j["truth_is"] = truth_what;
  j["conventions"] = conventionsText(conventions);
  for (const auto& b : blocks) j[b.metric->key] = b.detail;
  Json d{{"prediction", "voxels > 0 are vessel; their values are classes when the prediction is labelled"},
         {"truth", "voxels > 0 are vessel, except the ignore label's, which count neither way (truth_is says what the truth is)"}};
  for (const auto* m : scoreMetrics()) d[m->key] = m->definition;
  j["definitions"] = d;
  return j;
}

std::vector<std::string> headlineColumns() {
  std::vector<std::string> out;
  for (const auto* m : scoreMetrics())
    for (const auto& h : m->headline) out.push_back(h.column);
  return out;
}

std::map<int, std::string> classLegend(const nlohmann::ordered_json& sample) {
  std::map<int, std::string> legend;
  if (sample.contains("classes") && sample["classes"].is_object())
    for (const auto& [k, v] : sample["classes"].items()) {
      if (!v.is_string()) continue;
      try {
        const int value = std::stoi(k);
        if (value > 0 && value < 256) legend[value] = v.get<std::string>();
      } catch (const std::exception&) {}
    }
  return legend;
}

std::map<int, std::string> classLegend(const std::filesystem::path& sample_json) {
  std::ifstream in(sample_json);
  const Json j = Json::parse(in, nullptr, /*allow_exceptions=*/false);
  return j.is_discarded() ? std::map<int, std::string>{} : classLegend(j);
}

TruthFiles sampleTruth(const std::filesystem::path& dir) {
  if (!std::filesystem::is_directory(dir))
    throw InputError(dir.string(), 0, "is not a directory; allowed: a sample directory angiosynth generate wrote");
  const auto need = [&](const char* name) {
    const auto f = dir / name;
    if (!std::filesystem::is_regular_file(f))
      throw InputError(dir.string(), 0,
                       std::string("no ") + name + " in the sample directory; allowed: a directory angiosynth generate wrote (with volumes)");
    return f;
  };
  TruthFiles t;
  t.mask = need("mask.nii.gz"), t.centerline = need("centerline.nii.gz"), t.radius = need("radius.nii.gz");
  t.name = dir.string();
  t.what = "the sample's exact mask (mask.nii.gz: partial volume >= 0.5 or crossed by a centreline)";
  if (std::filesystem::is_regular_file(dir / "edges.csv") && std::filesystem::is_regular_file(dir / "nodes.csv")) t.edges = dir / "edges.csv";
  if (std::filesystem::is_regular_file(dir / "keypoints.csv")) t.keypoints = dir / "keypoints.csv";
  if (std::filesystem::is_regular_file(dir / "classes.nii.gz") && std::filesystem::is_regular_file(dir / "sample.json")) {
    t.classes = dir / "classes.nii.gz";
    t.legend = classLegend(dir / "sample.json");
  }
  // The distractor label of the sample's one degraded image that has one (with several, which
  // image was segmented is not known: none).
  std::vector<std::filesystem::path> distractors;
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    if (name.rfind("distractors_", 0) == 0 && name.size() > 7 && name.substr(name.size() - 7) == ".nii.gz") distractors.push_back(e.path());
  }
  if (distractors.size() == 1) t.distractors = distractors.front();
  return t;
}

TruthFiles annotationTruth(const std::filesystem::path& mask) {
  if (!std::filesystem::is_regular_file(mask))
    throw InputError(mask.string(), 0, "no such file; allowed: a NIfTI annotation (.nii, .nii.gz) or a sample directory angiosynth generate wrote");
  TruthFiles t;
  t.mask = mask;
  t.name = mask.string();
  t.what = "the annotation " + mask.filename().string() + " (voxels > 0 are vessel; values above 1 are classes)";
  return t;
}

CaseScores scoreCase(const std::filesystem::path& pred_file, const TruthFiles& files, const ScoreOptions& opt) {
  if (const auto why = opt.invalid(); !why.empty()) throw InputError("", 0, why);
  const NiftiVolume truth = readNiftiVolume(files.mask, opt.memory_limit, kBytesPerVoxel, "the truth mask");
  const NiftiVolume pred = readNiftiVolume(pred_file, opt.memory_limit, kBytesPerVoxel, "the prediction");
  checkSameGrid(pred, truth, pred_file.string(), files.mask.string(), opt.grid_tolerance_voxels);
  std::optional<NiftiVolume> centre, radius;
  if (!files.centerline.empty()) {
    centre = readNiftiVolume(files.centerline, opt.memory_limit, kBytesPerVoxel, "the truth centreline");
    checkSameGrid(*centre, truth, files.centerline.string(), files.mask.string(), opt.grid_tolerance_voxels);
  }
  if (!files.radius.empty()) {
    radius = readNiftiVolume(files.radius, opt.memory_limit, kBytesPerVoxel, "the truth radius");
    checkSameGrid(*radius, truth, files.radius.string(), files.mask.string(), opt.grid_tolerance_voxels);
  }
  if (radius && !centre) throw InputError(files.radius.string(), 0, "a radius volume is read along the centreline; give the centreline too");
  const ScoringCase c(opt, files, pred, truth, centre ? &centre->values : nullptr, radius ? &radius->values : nullptr);
  CaseScores s;
  s.prediction = pred_file.string();
  s.truth = files.name;
  s.truth_what = files.what;
  s.conventions = opt.conventions;
  for (const auto* m : scoreMetrics()) {
    Json block = m->compute(c);
    if (block.is_null()) continue;
    CaseScores::Block b{m, std::move(block), {}};
    for (const auto& h : m->headline) {
      const Json::json_pointer p(h.pointer);
      b.headline.push_back(b.detail.contains(p) && b.detail.at(p).is_number() ? std::optional<double>(b.detail.at(p).get<double>()) : std::nullopt);
    }
    s.blocks.push_back(std::move(b));
  }
  return s;
}

}  // namespace angiosynth
