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
  std::vector<double> upper;          // bin upper edges (INFINITY: the last, open bin); empty: the next bin's lower edge
  std::string name;                   // the legend's (empty: "curve k")
};

// The curve of a score result (`angiosynth score` JSON: its "calibre", or a dataset's mean per
// bin over the cases where it is defined). Throws InputError naming `file` when the JSON is not
// of that shape (wrong types, bins not increasing, recall outside [0, 1], cases with other bins).
CalibreCurve calibreCurve(const nlohmann::ordered_json& scores, const std::string& file);

// Where the plot puts things: radius on a square-root axis (the bins, which double in width, come
// out about evenly spaced, each drawn across its true extent; the open last bin as far again as
// its lower edge), recall linear.
struct CalibrePlotFrame {
  int width = 0, height = 0, left = 0, top = 0, plot_width = 0, plot_height = 0;
  double x_max = 1;  // radius (voxels) at the right end of the axis
  int x(double radius_voxels) const;
  int y(double recall) const;
  double binEnd(const CalibreCurve& c, std::size_t b) const;  // the upper edge drawn for bin b
};
CalibrePlotFrame calibrePlotFrame(const std::vector<CalibreCurve>& curves);

// Recall (0 … 1) against radius: each bin a step across its extent, a dot at its middle, curve k
// in colour k, named in the legend beside the plot; axes labelled "radius in voxels" and "recall".
Image8 plotCalibreCurves(const std::vector<CalibreCurve>& curves);

}  // namespace angiosynth
