// Recall of the exact centreline by the vessel's radius there.
#include "score/measures.hpp"
#include "score/metric.hpp"

namespace angiosynth {

extern const ScoreMetric kCalibreMetric{
    "calibre",
    "centreline voxels binned by the exact radius there (radius.nii.gz; in voxels of the smallest edge): recall = share in "
    "the prediction, truth_coverage = share in the truth mask (when the truth has a centreline and radius)",
    {},
    [](const ScoringCase& c) {
      if (!c.centreline || !c.radius) return nlohmann::ordered_json();
      return calibreRecall(c.prediction, c.truth, *c.centreline, *c.radius, c.options.bins_voxels, c.voxel_mm, "voxels");
    }};

extern const ScoreMetric kCalibreMmMetric{
    "calibre_mm", "the calibre bins with the radius in mm (when bins in mm are given)", {}, [](const ScoringCase& c) {
      if (c.options.bins_mm.empty() || !c.centreline || !c.radius) return nlohmann::ordered_json();
      return calibreRecall(c.prediction, c.truth, *c.centreline, *c.radius, c.options.bins_mm, 1.0, "mm");
    }};

}  // namespace angiosynth
