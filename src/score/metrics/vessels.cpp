// Vessels of the generating graph found in the prediction.
#include <algorithm>
#include <cmath>

#include "io/network_files.hpp"
#include "score/measures.hpp"
#include "score/metric.hpp"

namespace angiosynth {
namespace {

using Json = nlohmann::ordered_json;

// Vessels of the generating graph (root or bifurcation to the next bifurcation or terminal,
// through continuation nodes), each sampled every quarter of the smallest voxel edge: detected
// when at least 80 % of its sampled length lies on predicted voxels; tree length detected; the
// same by bifurcation level (the bifurcations between a vessel and its tree's root).
Json vesselDetection(const Volume<std::uint8_t>& pred, const VascularTree& t) {
  const VolumeGrid& g = pred.grid;
  const double step = smallestEdge(g) / 4;
  // Level and vessel of each segment, top down (an N-ary junction's links merged into its node).
  std::vector<std::int32_t> level(t.nodeCount(), 0), vessel(t.nodeCount(), -1);
  std::vector<std::int32_t> vessel_level;
  for (auto i : t.topDownOrder()) {
    if (t.isRoot(i) || t.isLink(i)) continue;
    const auto p = t.junction(t.parent[i]);
    if (t.isRoot(p) || t.graphType(p) != NodeType::Continuation) {
      level[i] = t.isRoot(p) ? 0 : level[p] + 1;
      vessel[i] = std::int32_t(vessel_level.size());
      vessel_level.push_back(level[i]);
    } else {
      level[i] = level[p];
      vessel[i] = vessel[p];
    }
  }
  std::vector<double> length(vessel_level.size(), 0), found(vessel_level.size(), 0);
  for (std::int32_t s = 0; s < t.nodeCount(); ++s) {
    if (t.isRoot(s) || t.isLink(s)) continue;
    const Vec3 a = t.position[t.parent[s]], b = t.position[s];
    const double len = distance(a, b);
    const int n = std::max(1, int(std::ceil(len / step)));
    for (int q = 0; q < n; ++q) {
      const Vec3 x = g.index(a + (b - a) * ((q + 0.5) / n));
      const std::int64_t i = std::llround(x.x), j = std::llround(x.y), k = std::llround(x.z);
      if (!g.contains(i, j, k)) continue;
      length[vessel[s]] += len / n;
      found[vessel[s]] += pred.at(i, j, k) ? len / n : 0.0;
    }
  }
  const int levels = vessel_level.empty() ? 0 : *std::max_element(vessel_level.begin(), vessel_level.end()) + 1;
  std::vector<double> lvl_len(levels, 0), lvl_found(levels, 0);
  std::vector<std::int64_t> lvl_n(levels, 0), lvl_det(levels, 0);
  double total = 0, total_found = 0;
  std::int64_t counted = 0, detected = 0;
  for (std::size_t v = 0; v < vessel_level.size(); ++v) {
    if (!(length[v] > 0)) continue;  // outside the image
    const bool det = found[v] >= 0.8 * length[v];
    const int l = vessel_level[v];
    ++counted, detected += det, total += length[v], total_found += found[v];
    ++lvl_n[l], lvl_det[l] += det, lvl_len[l] += length[v], lvl_found[l] += found[v];
  }
  Json by_level = Json::array();
  for (int l = 0; l < levels; ++l)
    if (lvl_n[l] > 0)
      by_level.push_back(Json{{"level", l},
                              {"vessels", lvl_n[l]},
                              {"detected", lvl_det[l]},
                              {"detected_rate", ratio(double(lvl_det[l]), double(lvl_n[l]))},
                              {"length_mm", lvl_len[l]},
                              {"length_detected", ratio(lvl_found[l], lvl_len[l])}});
  return Json{{"vessels", counted},
              {"detected", detected},
              {"detected_rate", ratio(double(detected), double(counted))},
              {"tree_length_mm", total},
              {"tree_length_detected", ratio(total_found, total)},
              {"by_level", by_level}};
}

}  // namespace

extern const ScoreMetric kVesselsMetric{
    "vessels",
    "vessels of the generating graph (root or bifurcation to the next bifurcation or terminal) sampled every quarter voxel at the "
    "nearest voxel centre; detected when >= 80 % of the sampled length is predicted; level = bifurcations from the root",
    {{"vessels_detected_rate", "/detected_rate"}, {"tree_length_detected", "/tree_length_detected"}},
    [](const ScoringCase& c) {
      if (c.files.edges.empty()) return Json();
      return vesselDetection(c.prediction, readNetwork(c.files.edges, 1, c.options.memory_limit).tree);
    }};

}  // namespace angiosynth
