// Scores class by class (artery and vein; the vessels of a challenge's label scheme), with class
// averages computed as the TopCoW 2024 evaluation computes them (Yang et al. 2023): over the
// classes present in the truth or the prediction, a class missing on one side scoring Dice 0.
#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <set>

#include <tbb/parallel_for.h>

#include "score/betti.hpp"
#include "score/label_volumes.hpp"
#include "score/measures.hpp"
#include "score/metric.hpp"
#include "score/skeleton.hpp"

namespace angiosynth {
namespace {

using Json = nlohmann::ordered_json;

// The numbers averaged over classes, by their place in a class's entry.
const std::vector<std::pair<const char*, const char*>> kAveraged{{"dice", "/overlap/dice"},
                                                                 {"cldice", "/cldice/cldice"},
                                                                 {"b0_error", "/b0/error"},
                                                                 {"hd95_mm", "/surface/hd95_mm"},
                                                                 {"hd_mm", "/surface/hd_mm"},
                                                                 {"recall", "/overlap/recall"},
                                                                 {"centreline_recall", "/centreline/recall"}};

// One class present in the truth or the prediction: its entry's scores. A class that is the whole
// of both masks (a single kind) reuses the case's skeletons.
void scoreClass(const ScoringCase& c, const Volume<std::uint8_t>& truth, const Volume<std::uint8_t>& pred, bool labelled, std::uint8_t value,
                const VoxelBox& box, bool whole, Json& k) {
  // Everything of this class in the box where it lies on either side, a voxel of background around.
  const Volume<std::uint8_t> tk = valueMask(truth, value, box);
  const Volume<std::uint8_t> pk = labelled ? valueMask(pred, value, box) : cropped(c.prediction, box);
  Json ov = overlapScores(pk, tk, c.topcow());
  if (labelled) {
    k["overlap"] = ov;
    k["cldice"] = whole ? clDice(c.predictionSkeleton(), c.truth, c.truthSkeleton(), c.prediction, c.topcow())
                        : clDice(skeletonize(pk), tk, skeletonize(tk), pk, c.topcow());
    const std::int64_t bt = countComponents(tk, 1, 26, false), bp = countComponents(pk, 1, 26, false);
    k["b0"] = Json{{"truth", bt}, {"prediction", bp}, {"error", std::abs(bp - bt)}};
    k["surface"] = surfaceScores(pk, tk, c.tolerance_mm, c.topcow(), c.options.missingDistanceMm());
  } else {
    k["overlap"] = Json{{"recall", ov["recall"]}};
  }
  if (c.centreline && c.radius) {
    Volume<float> ck = cropped(*c.centreline, box);
    for (std::size_t i = 0; i < ck.data.size(); ++i)
      if (!tk.data[i]) ck.data[i] = 0;
    std::int64_t n = 0, hit = 0;
    for (std::size_t i = 0; i < ck.data.size(); ++i)
      if (ck.data[i] > 0) ++n, hit += pk.data[i] != 0;
    k["centreline"] = Json{{"voxels", n}, {"recall", ratio(double(hit), double(n))}};
    k["calibre"] = calibreRecall(pk, tk, ck, cropped(*c.radius, box), c.options.bins_voxels, c.voxel_mm, "voxels");
  }
}

Json perClass(const ScoringCase& c) {
  const Volume<std::uint8_t>* truth = c.truthClasses();
  if (!truth) return Json();
  const bool labelled = c.predictionLabelled();
  const Volume<std::uint8_t>& pred = labelled ? c.predictionClasses() : c.prediction;
  // The prediction's classes are counted only when it has them.
  const auto nt = labelCounts(*truth), np = labelled ? labelCounts(pred) : std::array<std::int64_t, 256>{};
  const std::int64_t truth_total = std::count(c.truth.data.begin(), c.truth.data.end(), 1),
                     pred_total = std::count(c.prediction.data.begin(), c.prediction.data.end(), 1);
  std::set<int> values;
  for (const auto& [v, name] : c.files.legend) values.insert(v);
  for (int v = 1; v < 256; ++v)
    if (nt[std::size_t(v)] || (labelled && np[std::size_t(v)])) values.insert(v);
  Json warnings = Json::array();
  std::vector<int> order(values.begin(), values.end());
  std::vector<Json> entries(order.size());
  std::vector<std::size_t> scored;
  for (std::size_t e = 0; e < order.size(); ++e) {
    const int v = order[e];
    const std::string name = c.className(v);
    const std::int64_t in_truth = nt[std::size_t(v)], in_pred = labelled ? np[std::size_t(v)] : 0;
    const bool named = c.files.legend.count(v) || (c.options.scheme && c.options.scheme->labels.count(v));
    if (!named && (!c.files.legend.empty() || c.options.scheme))
      warnings.push_back(name + " occurs in the " + (in_truth ? "truth" : "prediction") + " but not in the legend; scored under that name");
    entries[e] = Json{{"label", v}, {"truth_voxels", in_truth}};
    if (labelled) entries[e]["prediction_voxels"] = in_pred;
    if (!in_truth && !in_pred)
      entries[e]["absent"] = true;  // in neither: not scored, not averaged
    else
      scored.push_back(e);
  }
  // Classes are independent: scored in parallel, each into its own entry, kept in label order.
  const auto boxes = labelled ? valueBoxes({truth, &pred}, 1) : valueBoxes({truth}, 1);
  tbb::parallel_for(std::size_t(0), scored.size(), [&](std::size_t q) {
    const std::size_t e = scored[q];
    const auto value = std::uint8_t(order[e]);
    const bool whole = labelled && nt[value] == truth_total && np[value] == pred_total;
    scoreClass(c, *truth, pred, labelled, value, boxes[value], whole, entries[e]);
  });
  Json per = Json::object();
  std::vector<std::vector<double>> averaged(kAveraged.size());
  const std::size_t present = scored.size();
  for (std::size_t e = 0; e < order.size(); ++e) {
    const Json& k = entries[e];
    for (std::size_t a = 0; a < kAveraged.size(); ++a) {
      const Json::json_pointer p(kAveraged[a].second);
      if (k.contains(p) && k.at(p).is_number()) averaged[a].push_back(k.at(p).get<double>());
    }
    per[c.className(order[e])] = k;
  }
  Json avg{{"classes", present}};
  for (std::size_t a = 0; a < kAveraged.size(); ++a) {
    double sum = 0;
    for (double x : averaged[a]) sum += x;
    avg[kAveraged[a].first] =
        averaged[a].empty() ? Json(present == 0 && c.topcow() ? Json(0.0) : Json(nullptr)) : Json(sum / double(averaged[a].size()));
    if (averaged[a].size() != present && !averaged[a].empty()) avg[std::string(kAveraged[a].first) + "_classes"] = averaged[a].size();
  }
  Json out{{"prediction",
            labelled ? "labelled: each class against the truth's voxels of that value" : "binary: what of each class it covers (recall-type scores)"},
           {"classes", per},
           {"class_average", avg}};
  if (!warnings.empty()) out["warnings"] = warnings;
  return out;
}

// Over cases: each class's numbers summarised over the cases where it is present on either side,
// and the class averages over every case.
Json perClassAcrossCases(const std::vector<const Json*>& blocks) {
  std::map<std::string, std::map<std::string, std::vector<double>>> by_class;
  std::map<std::string, std::vector<double>> averages;
  std::vector<std::string> order;
  for (const Json* b : blocks) {
    if (!b || !b->is_object()) continue;
    for (const auto& [name, k] : (*b)["classes"].items()) {
      if (std::find(order.begin(), order.end(), name) == order.end()) order.push_back(name);
      if (k.contains("absent")) continue;
      auto& m = by_class[name];
      m["present"].push_back(1);
      for (const auto& [key, pointer] : kAveraged) {
        const Json::json_pointer p(pointer);
        if (k.contains(p) && k.at(p).is_number()) m[key].push_back(k.at(p).get<double>());
      }
    }
    for (const auto& [key, pointer] : kAveraged)
      if ((*b)["class_average"].contains(key) && (*b)["class_average"][key].is_number())
        averages[key].push_back((*b)["class_average"][key].get<double>());
  }
  if (order.empty()) return Json();
  Json classes = Json::object();
  for (const auto& name : order) {
    Json k{{"cases_present", by_class[name]["present"].size()}};
    for (const auto& [key, pointer] : kAveraged)
      if (by_class[name].count(key)) k[key] = summaryOf(by_class[name][key]);
    classes[name] = k;
  }
  Json avg = Json::object();
  for (const auto& [key, pointer] : kAveraged)
    if (averages.count(key)) avg[key] = summaryOf(averages[key]);
  return Json{{"classes", classes}, {"class_average", avg}};
}

}  // namespace

extern const ScoreMetric kPerClassMetric{
    "per_class",
    "with a truth of several kinds (classes.nii.gz and its legend, a labelled mask, a label scheme): every class value in the "
    "legend, the truth or the prediction, named by the legend (\"label N\" and a warning when it lacks one). A labelled "
    "prediction is scored class by class against the truth's voxels of that value: overlap, clDice, b0 (26-connected pieces) "
    "and its error, surface distances, centreline recall and calibre; a binary one by what of each class it covers (recall, "
    "centreline recall, calibre). class_average: the mean over the classes present in the truth or the prediction (TopCoW "
    "2024), a class present on one side only scoring Dice 0 and, with --topcow, clDice 0 and HD95 and HD at the scheme's "
    "bound (90 mm; TopBrain 290 mm), else null and left out of the mean (its `<name>_classes` count then says over how many); "
    "classes in neither are listed as absent and not averaged",
    {{"class_avg_dice", "/class_average/dice"},
     {"class_avg_cldice", "/class_average/cldice"},
     {"class_avg_b0_error", "/class_average/b0_error"},
     {"class_avg_hd95_mm", "/class_average/hd95_mm"}},
    perClass,
    perClassAcrossCases};

}  // namespace angiosynth
