// The metrics a challenge's label scheme adds (score/label_schemes.hpp): detection of its small
// vessels by IoU, TopBrain's invalid neighbours, and TopCoW's Circle of Willis variants and
// topology matching, each case's verdicts here and their rates over cases in the aggregate.
#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include "score/betti.hpp"
#include "score/label_volumes.hpp"
#include "score/measures.hpp"
#include "score/metric.hpp"

namespace angiosynth {
namespace {

using Json = nlohmann::ordered_json;
using Neighbours = std::map<int, std::set<int>>;

using Counts = std::array<std::int64_t, 256>;

// Voxels of each value in both volumes at once (index = value).
Counts commonCounts(const Volume<std::uint8_t>& a, const Volume<std::uint8_t>& b) {
  Counts n{};
  for (std::size_t i = 0; i < a.data.size(); ++i)
    if (a.data[i] == b.data[i]) ++n[a.data[i]];
  return n;
}

// TP: in the truth with IoU ≥ the threshold; FN: in the truth below it; FP: only in the
// prediction; TN: in neither.
struct Detection {
  std::string result;
  double iou = 0;
};
Detection detect(const Counts& nt, const Counts& np, const Counts& common, int v, double threshold) {
  const std::int64_t a = nt[std::size_t(v)], b = np[std::size_t(v)];
  Detection d;
  if (a && b) {
    const std::int64_t both = common[std::size_t(v)];
    d.iou = double(both) / double(a + b - both);
  }
  d.result = a ? (d.iou >= threshold ? "TP" : "FN") : (b ? "FP" : "TN");
  return d;
}

std::vector<int> sorted(const Neighbours& n, int v) {
  const auto it = n.find(v);
  return it == n.end() ? std::vector<int>{} : std::vector<int>(it->second.begin(), it->second.end());
}

bool touches(const Neighbours& n, int a, int b) {
  const auto it = n.find(a);
  return it != n.end() && it->second.count(b);
}

// TopCoW's variant vectors: anterior (L-A1, Acom, 3rd-A2, R-A1), posterior (L-Pcom, L-P1, R-P1,
// R-Pcom); an A1 is there when the ACA touches its ICA, a P1 when the PCA touches the BA.
std::pair<std::vector<int>, std::vector<int>> cowVariant(const std::array<std::int64_t, 256>& n, const Neighbours& nb) {
  const auto has = [&](int v) { return n[std::size_t(v)] > 0; };
  return {{has(12) && touches(nb, 12, 6), has(10), has(15), has(11) && touches(nb, 11, 4)},
          {has(9), has(3) && touches(nb, 3, 1), has(2) && touches(nb, 2, 1), has(8)}};
}

std::string variantName(const char* region, const std::vector<int>& v) {
  // Appended piecewise: GCC 12 warns falsely (-Wrestrict) on "_" + string.
  std::string s = "Var_";
  s += region;
  for (int x : v) (s += '_') += std::to_string(x);
  return s;
}

// Left and right swapped: the left vessel's median lies right of the right one's (patient left
// is world −x in NIfTI's RAS frame). Anterior: the ICAs, else the ACAs; posterior: the PCAs.
bool leftRightFlipped(const ScoringCase& c, const Volume<std::uint8_t>& p, const std::array<std::int64_t, 256>& np, bool anterior) {
  std::pair<int, int> lr{0, 0};
  if (anterior)
    lr = np[6] && np[4] ? std::pair{6, 4} : np[12] && np[11] ? std::pair{12, 11} : std::pair{0, 0};
  else if (np[3] && np[2])
    lr = {3, 2};
  if (!lr.first) return false;
  const auto& m = c.prediction_file.affine;
  const auto median_left = [&](int v) {
    std::vector<double> x;
    const VolumeGrid& g = p.grid;
    for (std::int64_t k = 0; k < g.dims[2]; ++k)
      for (std::int64_t j = 0; j < g.dims[1]; ++j)
        for (std::int64_t i = 0; i < g.dims[0]; ++i)
          if (p.at(i, j, k) == v) x.push_back(-(m[0] * double(i) + m[1] * double(j) + m[2] * double(k) + m[3]));
    std::sort(x.begin(), x.end());
    const std::size_t n = x.size();
    return n % 2 ? x[n / 2] : 0.5 * (x[n / 2 - 1] + x[n / 2]);
  };
  return median_left(lr.first) < median_left(lr.second);
}

// 26-connected pieces of class v, counted within its box.
std::int64_t pieces(const Volume<std::uint8_t>& classes, const std::array<VoxelBox, 256>& boxes, int v) {
  const VoxelBox& box = boxes[std::size_t(v)];
  return box.empty() ? 0 : countComponents(valueMask(classes, std::uint8_t(v), box), 1, 26, false);
}

Json labelSchemeScores(const ScoringCase& c) {
  if (!c.options.scheme) return Json();
  const LabelScheme& s = *c.options.scheme;
  const Volume<std::uint8_t>* truth = c.truthClasses();
  if (!truth) return Json();
  const Volume<std::uint8_t>& pred = c.predictionClasses();
  const Counts nt = labelCounts(*truth), np = labelCounts(pred), common = commonCounts(*truth, pred);
  Json out{{"scheme", s.name}, {"source", s.source}};
  if (!s.detection_labels.empty()) {
    Json labels = Json::object();
    for (int v : s.detection_labels) {
      const Detection d = detect(nt, np, common, v, s.detection_iou);
      labels[c.className(v)] = Json{{"label", v}, {"iou", d.iou}, {"detection", d.result}};
    }
    out["detection"] = Json{{"vessels", s.detection_name}, {"iou_threshold", s.detection_iou}, {"labels", labels}};
  }
  const Neighbours nb_pred = labelNeighbours(pred);
  if (!s.valid_neighbours.empty()) {
    Json labels = Json::object();
    double sum = 0;
    int n = 0;
    for (int v = 1; v < 256; ++v) {
      if (!np[std::size_t(v)]) continue;
      const auto valid_it = s.valid_neighbours.find(v);
      Json invalid = Json::array();
      for (int w : sorted(nb_pred, v))
        if (valid_it == s.valid_neighbours.end() || std::find(valid_it->second.begin(), valid_it->second.end(), w) == valid_it->second.end())
          invalid.push_back(c.className(w));
      labels[c.className(v)] = Json{{"label", v}, {"invalid", invalid}, {"error", invalid.size()}};
      sum += double(invalid.size());
      ++n;
    }
    out["invalid_neighbours"] = Json{{"labels", labels}, {"class_average", n ? Json(sum / n) : Json(nullptr)}};
  }
  if (s.circle_of_willis) {
    const Neighbours nb_truth = labelNeighbours(*truth);
    const auto [ta, tp] = cowVariant(nt, nb_truth);
    const auto [pa, pp] = cowVariant(np, nb_pred);
    Json cow{{"truth", Json{{"anterior", variantName("Ant", ta)}, {"posterior", variantName("Pos", tp)}}},
             {"prediction", Json{{"anterior", variantName("Ant", pa)}, {"posterior", variantName("Pos", pp)}}},
             {"variant_match", Json{{"anterior", ta == pa}, {"posterior", tp == pp}}}};
    const auto truth_boxes = valueBoxes({truth}, 1), pred_boxes = valueBoxes({&pred}, 1);
    Json topo = Json::object();
    for (const bool anterior : {true, false}) {
      const std::vector<int> region = anterior ? std::vector<int>{10, 11, 12, 15} : std::vector<int>{2, 3, 8, 9};
      Json labels = Json::object();
      std::string why;
      for (int v : region) {
        const Detection d = detect(nt, np, common, v, s.detection_iou);
        const std::int64_t bt = pieces(*truth, truth_boxes, v), bp = pieces(pred, pred_boxes, v);
        const auto ntv = sorted(nb_truth, v), npv = sorted(nb_pred, v);
        labels[c.className(v)] =
            Json{{"detection", d.result}, {"b0_truth", bt}, {"b0_prediction", bp}, {"neighbours_truth", ntv}, {"neighbours_prediction", npv}};
        if (!why.empty()) continue;
        why = c.className(v);
        if (d.result != "TP" && d.result != "TN")
          (why += " detection ") += d.result;
        else if (ntv != npv)
          why += " touches other classes than in the truth";
        else if (bt != bp)
          ((((why += " in ") += std::to_string(bp)) += " pieces, the truth in ") += std::to_string(bt));
        else
          why.clear();
      }
      const bool flipped = leftRightFlipped(c, pred, np, anterior);
      if (why.empty() && flipped) why = "left and right swapped";
      topo[anterior ? "anterior" : "posterior"] =
          Json{{"match", why.empty()}, {"why_not", why.empty() ? Json(nullptr) : Json(why)}, {"left_right_flipped", flipped}, {"labels", labels}};
    }
    cow["topology"] = topo;
    out["circle_of_willis"] = cow;
  }
  return out;
}

// TopCoW's and TopBrain's sklearn balanced accuracy: the mean over the true classes of the share
// of their cases predicted as that class.
double balancedAccuracy(const std::vector<std::string>& truth, const std::vector<std::string>& pred) {
  std::map<std::string, std::pair<int, int>> per;  // class → (cases, right)
  for (std::size_t i = 0; i < truth.size(); ++i) {
    auto& [n, right] = per[truth[i]];
    ++n;
    right += pred[i] == truth[i];
  }
  double sum = 0;
  for (const auto& [k, v] : per) sum += double(v.second) / double(v.first);
  return per.empty() ? 0.0 : sum / double(per.size());
}

Json meanAndSd(const std::vector<double>& v) {
  double m = 0, ss = 0;
  for (double x : v) m += x;
  m /= double(std::max<std::size_t>(1, v.size()));
  for (double x : v) ss += (x - m) * (x - m);
  return Json{{"mean", m}, {"sd", std::sqrt(ss / double(std::max<std::size_t>(1, v.size())))}};
}

Json labelSchemeAcrossCases(const std::vector<const Json*>& blocks) {
  Json out = Json::object();
  std::map<std::string, std::map<std::string, int>> counts;
  std::vector<std::string> order;
  std::vector<std::string> ant_t, ant_p, pos_t, pos_p, ant_topo, pos_topo;
  std::vector<double> nb_err;
  int cases = 0;
  for (const Json* b : blocks) {
    if (!b || !b->is_object()) continue;
    ++cases;
    if (b->contains("detection"))
      for (const auto& [name, d] : (*b)["detection"]["labels"].items()) {
        if (!counts.count(name)) order.push_back(name);
        ++counts[name][d["detection"].get<std::string>()];
      }
    if (b->contains("invalid_neighbours") && (*b)["invalid_neighbours"]["class_average"].is_number())
      nb_err.push_back((*b)["invalid_neighbours"]["class_average"].get<double>());
    if (b->contains("circle_of_willis")) {
      const Json& cow = (*b)["circle_of_willis"];
      ant_t.push_back(cow["truth"]["anterior"]), ant_p.push_back(cow["prediction"]["anterior"]);
      pos_t.push_back(cow["truth"]["posterior"]), pos_p.push_back(cow["prediction"]["posterior"]);
      ant_topo.push_back(cow["topology"]["anterior"]["match"].get<bool>() ? ant_t.back() : "FAIL");
      pos_topo.push_back(cow["topology"]["posterior"]["match"].get<bool>() ? pos_t.back() : "FAIL");
    }
  }
  if (!cases) return Json();
  out["cases"] = cases;
  if (!order.empty()) {
    Json labels = Json::object();
    std::vector<double> precision, recall, f1;
    for (const auto& name : order) {
      auto& k = counts[name];
      const int tp = k["TP"], fp = k["FP"], fn = k["FN"], tn = k["TN"];
      // Undefined ratios count as 0, as both evaluations average them.
      precision.push_back(tp + fp ? double(tp) / (tp + fp) : 0.0);
      recall.push_back(tp + fn ? double(tp) / (tp + fn) : 0.0);
      f1.push_back(tp + fp + fn ? 2.0 * tp / (2.0 * tp + fp + fn) : 0.0);
      labels[name] =
          Json{{"TP", tp}, {"FP", fp}, {"FN", fn}, {"TN", tn}, {"precision", precision.back()}, {"recall", recall.back()}, {"f1", f1.back()}};
    }
    out["detection"] = Json{{"labels", labels}, {"precision", meanAndSd(precision)}, {"recall", meanAndSd(recall)}, {"f1", meanAndSd(f1)}};
  }
  if (!nb_err.empty()) out["invalid_neighbour_error"] = summaryOf(nb_err);
  if (!ant_t.empty())
    out["circle_of_willis"] =
        Json{{"variant_balanced_accuracy", Json{{"anterior", balancedAccuracy(ant_t, ant_p)}, {"posterior", balancedAccuracy(pos_t, pos_p)}}},
             {"topology_match_rate", Json{{"anterior", balancedAccuracy(ant_t, ant_topo)}, {"posterior", balancedAccuracy(pos_t, pos_topo)}}}};
  return out;
}

}  // namespace

extern const ScoreMetric kLabelSchemeMetric{
    "label_scheme",
    "with --label-scheme: the challenge's own metrics on the class values. detection: each listed small vessel per case TP "
    "(in the truth, IoU >= 0.25), FN (in the truth, IoU below), FP (in the prediction only) or TN (in neither); over cases "
    "precision, recall and F1 per vessel (0 where undefined) and their means (TopCoW 2024 group 2, TopBrain 2025 side roads). "
    "invalid_neighbours (TopBrain): for each class in the prediction, the classes it touches (26-neighbours) that the "
    "scheme does not allow, their count averaged over those classes. circle_of_willis (TopCoW): the anterior (L-A1, Acom, "
    "3rd-A2, R-A1) and posterior (L-Pcom, L-P1, R-P1, R-Pcom) variant vectors of truth and prediction (an A1 where the ACA "
    "touches its ICA, a P1 where the PCA touches the BA) and whether they match; topology matching per region: every region "
    "label detected TP or TN, touching the same classes, in as many pieces as in the truth, and left and right not swapped "
    "(the medians of the world x of the ICAs, else ACAs, or PCAs); over cases the variant-balanced accuracy of the "
    "classification and of the topology match (a failed match counting as a wrong class)",
    {{"invalid_neighbour_error", "/invalid_neighbours/class_average"}},
    labelSchemeScores,
    labelSchemeAcrossCases};

}  // namespace angiosynth
