#pragma once
// The calibre curve as a picture: recall by vessel radius for one or more score results, one
// coloured curve each, drawn into an 8-bit RGB image (written as PNG by the caller).
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "io/volume_writers.hpp"

namespace angiosynth {

struct CalibreCurve {
  std::vector<double> lower, recall;  // bin lower edges (radius in voxels) and recall (NaN: no voxel)
};

// The curve of a score result (`angiosynth score` JSON: its "calibre", or a dataset's mean per
// bin over the cases where it is defined). Throws InputError naming `file` when the JSON is not
// of that shape (wrong types, bins not increasing, recall outside [0, 1], cases with other bins).
CalibreCurve calibreCurve(const nlohmann::ordered_json& scores, const std::string& file);

// Recall (0 … 1) against the bins' lower edges, equally spaced; curve k in colour k (the legend:
// numbers 1, 2, … beside the curves' colours); axes labelled "radius voxels" and "recall".
Image8 plotCalibreCurves(const std::vector<CalibreCurve>& curves);

}  // namespace angiosynth
