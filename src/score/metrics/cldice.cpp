// clDice from the skeletons, and from the exact centreline as the truth's skeleton.
#include "score/measures.hpp"
#include "score/metric.hpp"

namespace angiosynth {

extern const ScoreMetric kClDiceMetric{
    "cldice",
    "clDice = 2 Tprec Tsens / (Tprec + Tsens), Tprec = share of the prediction's skeleton in the truth mask, Tsens = share "
    "of the truth's skeleton in the prediction; skeletons by Lee's thinning in scikit-image's order (skeletonize_3d); "
    "`exact_centreline` takes the exact centreline as the truth's skeleton (when the truth has one); null when a skeleton is "
    "empty (TopCoW: that skeleton's share is 0, and clDice 0 when both shares are)",
    {{"cldice", "/skeletons/cldice"}, {"cldice_exact_centreline", "/exact_centreline/cldice"}},
    [](const ScoringCase& c) {
      nlohmann::ordered_json j{{"skeletons", clDice(c.predictionSkeleton(), c.truth, c.truthSkeleton(), c.prediction, c.topcow())}};
      j["exact_centreline"] =
          c.centreline ? clDice(c.predictionSkeleton(), c.truth, binaryMask(*c.centreline), c.prediction, c.topcow()) : nlohmann::ordered_json();
      return j;
    }};

}  // namespace angiosynth
