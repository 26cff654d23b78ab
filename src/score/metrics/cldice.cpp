// clDice from the skeletons, and from the exact centreline as the truth's skeleton.
#include "score/measures.hpp"
#include "score/metric.hpp"

namespace angiosynth {

extern const ScoreMetric kClDiceMetric{
    "cldice",
    "clDice = 2 Tprec Tsens / (Tprec + Tsens), Tprec = share of the prediction's skeleton in the truth mask, Tsens = share "
    "of the truth's skeleton in the prediction; skeletons by Lee's thinning in scikit-image's order (skeletonize_3d); "
    "`exact_centreline` takes the exact centreline as the truth's skeleton; null when a skeleton is empty",
    {{"cldice", "/skeletons/cldice"}, {"cldice_exact_centreline", "/exact_centreline/cldice"}},
    [](const ScoringCase& c) {
      return nlohmann::ordered_json{{"skeletons", clDice(c.predictionSkeleton(), c.truth, c.truthSkeleton(), c.prediction)},
                                    {"exact_centreline", clDice(c.predictionSkeleton(), c.truth, binaryMask(c.centreline), c.prediction)}};
    }};

}  // namespace angiosynth
