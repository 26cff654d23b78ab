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
             ? "TopCoW: 26-neighbour borders, 90 mm for a surface distance when one mask is empty, Dice and Jaccard 0 when both are"
             : "default: 6-neighbour borders, null for a surface distance when one mask is empty, Dice and Jaccard 1 when both are";
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
  return "";
}

ScoringCase::ScoringCase(const ScoreOptions& o, const TruthFiles& f, const NiftiVolume& pred, const NiftiVolume& t, const Volume<float>& centre,
                         const Volume<float>& rad)
    : options(o),
      files(f),
      prediction_file(pred),
      truth_file(t),
      prediction(binaryMask(pred.values)),
      truth(binaryMask(t.values)),
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

NiftiVolume ScoringCase::readTruthVolume(const std::filesystem::path& file, const char* what) const {
  NiftiVolume v = readNiftiVolume(file, options.memory_limit, kBytesPerVoxel, what);
  checkSameGrid(v, truth_file, file.string(), files.mask.string());
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
  j["conventions"] = conventionsText(conventions);
  for (const auto& b : blocks) j[b.metric->key] = b.detail;
  Json d{{"prediction", "voxels > 0 are vessel"}, {"truth", "the sample's mask.nii.gz (partial volume >= 0.5 or crossed by a centreline)"}};
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
  if (std::filesystem::is_regular_file(dir / "edges.csv") && std::filesystem::is_regular_file(dir / "nodes.csv")) t.edges = dir / "edges.csv";
  if (std::filesystem::is_regular_file(dir / "keypoints.csv")) t.keypoints = dir / "keypoints.csv";
  if (std::filesystem::is_regular_file(dir / "classes.nii.gz") && std::filesystem::is_regular_file(dir / "sample.json")) {
    t.classes = dir / "classes.nii.gz";
    t.legend = classLegend(dir / "sample.json");
  }
  return t;
}

CaseScores scoreCase(const std::filesystem::path& pred_file, const TruthFiles& files, const ScoreOptions& opt) {
  if (const auto why = opt.invalid(); !why.empty()) throw InputError("", 0, why);
  const NiftiVolume truth = readNiftiVolume(files.mask, opt.memory_limit, kBytesPerVoxel, "the truth mask");
  const NiftiVolume pred = readNiftiVolume(pred_file, opt.memory_limit, kBytesPerVoxel, "the prediction");
  checkSameGrid(pred, truth, pred_file.string(), files.mask.string());
  const NiftiVolume centre = readNiftiVolume(files.centerline, opt.memory_limit, kBytesPerVoxel, "the truth centreline");
  const NiftiVolume radius = readNiftiVolume(files.radius, opt.memory_limit, kBytesPerVoxel, "the truth radius");
  checkSameGrid(centre, truth, files.centerline.string(), files.mask.string());
  checkSameGrid(radius, truth, files.radius.string(), files.mask.string());
  const ScoringCase c(opt, files, pred, truth, centre.values, radius.values);
  CaseScores s;
  s.prediction = pred_file.string();
  s.truth = files.name;
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
