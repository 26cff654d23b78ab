// Bifurcations and endpoints of the prediction's skeleton against the truth graph's.
#include "score/keypoints.hpp"
#include "score/measures.hpp"
#include "score/metric.hpp"

namespace angiosynth {

extern const ScoreMetric kKeyPointsMetric{
    "keypoints",
    "bifurcations and endpoints of the prediction's skeleton (26-neighbour count 1: an endpoint; each 26-connected "
    "cluster of voxels with 3 or more: one bifurcation at its centroid) against the truth graph's bifurcations and "
    "endpoints (terminals and roots, keypoints.csv), matched one to one closest first within max(2 voxels, the truth "
    "point's radius); precision, recall, F1",
    {{"bifurcation_f1", "/bifurcations/f1"}, {"endpoint_f1", "/endpoints/f1"}},
    [](const ScoringCase& c) {
      using Json = nlohmann::ordered_json;
      if (c.files.keypoints.empty()) return Json();
      const KeyPoints found = skeletonKeyPoints(c.predictionSkeleton()), known = truthKeyPoints(c.files.keypoints, c.truth.grid);
      const double tol = 2 * c.voxel_mm;
      return Json{{"tolerance_mm", Json{{"at_least", tol}, {"or", "the truth point's radius, if larger"}}},
                  {"bifurcations", matchKeyPoints(found.bifurcations, known.bifurcations, tol)},
                  {"endpoints", matchKeyPoints(found.endpoints, known.endpoints, tol)}};
    }};

}  // namespace angiosynth
