// False positives on distractors: of the voxels a degraded image shows that are not vessels
// (blobs, tubes, plates, bone, calcified plaque: its distractor label), the share the prediction
// calls vessel, per kind, and the share of all its false positives that lie on them. Present when
// the truth has a distractor label (a sample with one degraded image that has one, a dataset case).
#include "core/distractor_kind.hpp"
#include "score/metric.hpp"

namespace angiosynth {
namespace {

using Json = nlohmann::ordered_json;

Json computeDistractors(const ScoringCase& c) {
  if (c.files.distractors.empty()) return nullptr;
  const NiftiVolume d = c.readTruthVolume(c.files.distractors, "distractor label");
  std::int64_t voxels[kDistractorKinds + 1] = {}, called[kDistractorKinds + 1] = {};
  std::int64_t false_positives = 0;
  for (std::size_t v = 0; v < c.prediction.data.size(); ++v) {
    const bool fp = c.prediction.data[v] && !c.truth.data[v] && !c.ignore.data[v];
    false_positives += fp;
    const int kind = int(d.values.data[v]);
    if (kind < 1 || kind > kDistractorKinds || c.truth.data[v] || c.ignore.data[v]) continue;
    ++voxels[kind];
    called[kind] += fp;
  }
  std::int64_t all = 0, all_called = 0;
  Json kinds = Json::object();
  for (int k = 1; k <= kDistractorKinds; ++k) {
    all += voxels[k], all_called += called[k];
    if (voxels[k])
      kinds[distractorName(std::uint8_t(k))] = {
          {"voxels", voxels[k]}, {"called_vessel", called[k]}, {"share_called_vessel", double(called[k]) / voxels[k]}};
  }
  return {{"label", c.files.distractors.filename().string()},
          {"voxels", all},
          {"called_vessel", all_called},
          {"share_called_vessel", all ? Json(double(all_called) / all) : Json(nullptr)},
          {"false_positives", false_positives},
          {"share_of_false_positives", false_positives ? Json(double(all_called) / false_positives) : Json(nullptr)},
          {"by_kind", kinds}};
}

}  // namespace

extern const ScoreMetric kDistractorsMetric{
    "distractors",
    "false positives on the structures the degraded image shows that are not vessels (its distractor label: blobs, tubes, plates, bone, "
    "calcified plaque): voxels of each kind the prediction calls vessel over the kind's voxels, and the share of the prediction's false "
    "positives that lie on them; vessel-mask and ignore voxels excluded",
    {{"distractor_share_called_vessel", "/share_called_vessel"}, {"distractor_share_of_false_positives", "/share_of_false_positives"}},
    computeDistractors};

}  // namespace angiosynth
