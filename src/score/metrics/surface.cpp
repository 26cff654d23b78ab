// Distances between the borders of the prediction and of the truth mask.
#include "score/measures.hpp"
#include "score/metric.hpp"

namespace angiosynth {

extern const ScoreMetric kSurfaceMetric{
    "surface",
    "distances in mm between border voxel centres (spacing per axis); HD the largest directed distance; HD95 the larger of the "
    "two directed 95th percentiles (linear interpolation, NumPy's default); ASSD the mean over both borders' distances; MASD "
    "the mean of the two directed means; NSD the share of both borders within tolerance_mm of the other",
    {{"hd_mm", "/hd_mm"}, {"hd95_mm", "/hd95_mm"}, {"assd_mm", "/assd_mm"}, {"masd_mm", "/masd_mm"}, {"nsd", "/nsd"}},
    [](const ScoringCase& c) { return surfaceScores(c.prediction, c.truth, c.tolerance_mm, c.topcow(), c.options.missingDistanceMm()); }};

}  // namespace angiosynth
