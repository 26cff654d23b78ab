// The score metrics by name: the order of a case's results and of the CSV's columns.
#include <sstream>

#include "score/metric.hpp"

namespace angiosynth {

extern const ScoreMetric kOverlapMetric, kSurfaceMetric, kCentrelineMetric, kVesselsMetric, kClDiceMetric, kTopologyMetric, kKeyPointsMetric,
    kCalibreMetric, kCalibreMmMetric, kPerClassMetric, kBoundaryIoUMetric, kLabelSchemeMetric, kDistractorsMetric;

// clang-format off
const std::vector<const ScoreMetric*>& scoreMetrics() {
  // New metrics go last, so that the CSV's existing columns keep their places (per_class moved
  // behind boundary_iou when it gained its class-average columns).
  static const std::vector<const ScoreMetric*> all{&kOverlapMetric,   &kSurfaceMetric, &kCentrelineMetric, &kVesselsMetric,
                                                   &kClDiceMetric,    &kTopologyMetric, &kKeyPointsMetric, &kCalibreMetric,
                                                   &kCalibreMmMetric, &kBoundaryIoUMetric, &kPerClassMetric, &kLabelSchemeMetric,
                                                   &kDistractorsMetric};
  return all;
}
// clang-format on

const ScoreMetric* findScoreMetric(const std::string& key) {
  for (const auto* m : scoreMetrics())
    if (key == m->key) return m;
  return nullptr;
}

std::string scoreMetricReference() {
  std::ostringstream o;
  for (const auto* m : scoreMetrics()) {
    o << "- **`" << m->key << "`**: " << m->definition << ".";
    if (!m->headline.empty()) {
      o << " CSV columns:";
      for (std::size_t k = 0; k < m->headline.size(); ++k) o << (k ? ", `" : " `") << m->headline[k].column << "`";
      o << ".";
    }
    o << "\n";
  }
  return o.str();
}

}  // namespace angiosynth
