// The exact centreline's share in the prediction.
#include "score/measures.hpp"
#include "score/metric.hpp"

namespace angiosynth {

extern const ScoreMetric kCentrelineMetric{
    "centreline",
    "share of the exact centreline's voxels (centerline.nii.gz) in the prediction: clDice's topology sensitivity with the exact "
    "skeleton (when the truth has a centreline)",
    {{"centreline_recall", "/recall"}},
    [](const ScoringCase& c) {
      if (!c.centreline) return nlohmann::ordered_json();
      std::int64_t n = 0, hit = 0;
      for (std::size_t i = 0; i < c.centreline->data.size(); ++i)
        if (c.centreline->data[i] > 0) ++n, hit += c.prediction.data[i] != 0;
      return nlohmann::ordered_json{{"voxels", n}, {"recall", ratio(double(hit), double(n))}};
    }};

}  // namespace angiosynth
