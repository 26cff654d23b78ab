#pragma once
// Reference segmenters, so that every benchmark has baseline rows: a global threshold by Otsu's
// rule (Otsu 1979) and multiscale Hessian vesselness (Frangi et al. 1998, Sato et al. 1998,
// Jerman et al. 2016) thresholded by a stated rule. One front door: options, segment(), summary.
#include <cstdint>
#include <string>
#include <vector>

#include "raster/volume.hpp"

namespace angiosynth {

struct SegmentOptions {
  std::string method = "frangi";   // a registered method: otsu, frangi, sato, jerman
  std::vector<double> sigmas_mm;   // vesselness scales (Gaussian σ in mm); empty: 1, 2, 3 voxels
  bool bright = true;              // vessels brighter than their surroundings (false: darker)
  double alpha = 0.5, beta = 0.5;  // Frangi: sensitivity to plates and to blobs
  double gamma = 15;               // Frangi: sensitivity to structure (Hessian norm); 0: half the largest norm
  double tau = 0.75;               // Jerman: share of the largest eigenvalue that counts as full response
  // The mask: response ≥ threshold_fraction × the largest response (vesselness), or the image
  // above Otsu's threshold (otsu; the negated image for dark vessels); an explicit threshold on
  // the response when `threshold` is set.
  double threshold_fraction = 0.02;
  bool has_threshold = false;
  double threshold = 0;
};

struct SegmentSummary {
  std::string method;
  std::vector<double> sigmas_voxels;  // the scales per axis (x), in voxels
  double threshold = 0;               // on the response (the image for otsu)
  double max_response = 0;
  std::int64_t voxels = 0;  // voxels in the mask
  double seconds = 0;
};

// Bytes per voxel segment() holds beside the image (for the memory check before it runs).
std::uint64_t segmentBytesPerVoxel(const SegmentOptions& o);

// The mask (1 vessel, 0 not) and, when `response` is given, the response it thresholded (the
// vesselness, or for otsu the image, negated for dark vessels). Throws std::invalid_argument for an unknown method or a bad
// option, naming what is allowed.
Volume<std::uint8_t> segment(const Volume<float>& image, const SegmentOptions& o, SegmentSummary& summary, Volume<float>* response = nullptr);

// The registered methods, in the order `--help` lists them, with one line each.
struct SegmentMethod {
  const char* name;
  const char* summary;
};
const std::vector<SegmentMethod>& segmentMethods();

// Otsu's threshold over a 256-bin histogram of the values (as scikit-image computes it).
double otsuThreshold(const float* values, std::size_t count);

}  // namespace angiosynth
