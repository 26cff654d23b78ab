// Overlap of the prediction with the truth mask, voxel by voxel.
#include "score/measures.hpp"
#include "score/metric.hpp"

namespace angiosynth {

extern const ScoreMetric kOverlapMetric{
    "overlap",
    "Dice 2TP/(2TP+FP+FN), Jaccard TP/(TP+FP+FN), precision TP/(TP+FP), recall TP/(TP+FN); null when the denominator is 0",
    {{"dice", "/dice"}, {"jaccard", "/jaccard"}, {"precision", "/precision"}, {"recall", "/recall"}},
    [](const ScoringCase& c) { return overlapScores(c.prediction, c.truth, c.topcow()); }};

}  // namespace angiosynth
