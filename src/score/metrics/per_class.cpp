// Scores by kind of vessel (artery, vein) where the truth has several.
#include <algorithm>
#include <cmath>
#include "score/measures.hpp"
#include "score/metric.hpp"

namespace angiosynth {
namespace {

using Json = nlohmann::ordered_json;

Json perClass(const ScoringCase& c) {
  const TruthFiles& files = c.files;
  const VolumeGrid& g = c.truth.grid;
  if (files.classes.empty() || files.legend.size() < 2) return Json();
  const NiftiVolume cls = c.readTruthVolume(files.classes, "the truth classes");
  const auto& pred = c.prediction_file;
  // A prediction labelled by kind (values above 1) is scored class by class; a binary one only
  // by what each class of the truth keeps (recall, centreline, calibre).
  const bool labelled = std::any_of(pred.values.data.begin(), pred.values.data.end(), [](float v) { return v > 1.5f; });
  Json per = Json::object();
  for (const auto& [value, name] : files.legend) {
    Volume<std::uint8_t> pk(g), tk(g);
    Volume<float> ck(g);
    for (std::size_t i = 0; i < pk.data.size(); ++i) {
      tk.data[i] = std::lround(cls.values.data[i]) == value;
      pk.data[i] = labelled ? std::lround(pred.values.data[i]) == value : c.prediction.data[i];
      ck.data[i] = tk.data[i] ? c.centreline.data[i] : 0.0f;
    }
    Json k{{"label", value}};
    Json ov = overlapScores(pk, tk, c.topcow());
    if (!labelled) ov = Json{{"recall", ov["recall"]}};
    k["overlap"] = ov;
    if (labelled) k["surface"] = surfaceScores(pk, tk, c.tolerance_mm, c.topcow());
    std::int64_t n = 0, hit = 0;
    for (std::size_t i = 0; i < ck.data.size(); ++i)
      if (ck.data[i] > 0) ++n, hit += pk.data[i] != 0;
    k["centreline"] = Json{{"voxels", n}, {"recall", ratio(double(hit), double(n))}};
    k["calibre"] = calibreRecall(pk, tk, ck, c.radius, c.options.bins_voxels, c.voxel_mm, "voxels");
    per[name] = k;
  }
  return Json{{"prediction", labelled ? "labelled by kind (the truth's class values)" : "binary: recall-type scores only"}, {"classes", per}};
}

}  // namespace

extern const ScoreMetric kPerClassMetric{
    "per_class",
    "with a truth of several kinds (classes.nii.gz, its legend in sample.json): each class's voxels against the "
    "prediction's voxels of that value (a prediction labelled by kind), or, for a binary prediction, the share of each "
    "class the prediction covers (recall, centreline recall, calibre)",
    {},
    perClass};

}  // namespace angiosynth
