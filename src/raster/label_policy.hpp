#pragma once
// Label policies: which voxels a segmenter is taught to call vessel. The mask channel keeps one
// fixed rule (partial volume ≥ ½ or crossed by a centreline); a policy derives the training
// label from the exact partial volume, the centrelines and, for `visible`, the degraded image.
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/vascular_tree.hpp"
#include "raster/volume.hpp"

namespace angiosynth {

struct GroundTruthVolumes;

struct LabelPolicy {
  // binary: the mask; threshold: partial volume ≥ threshold; visible: mask voxels whose
  // noise-free contrast in the degraded image is ≥ visible_snr × the noise σ there; soft: the
  // partial volume itself (float); ignore: vessel at partial volume ≥ the band's high end, the
  // ignore label on the ambiguous band (low, high) and on centreline voxels below it.
  std::string name = "binary";
  double threshold = 0.5;
  double visible_snr = 2;
  std::vector<double> ignore_band{0.25, 0.75};  // low, high
  double ignoreLow() const { return ignore_band[0]; }
  double ignoreHigh() const { return ignore_band[1]; }
  bool writesLabel() const { return name != "binary"; }
  bool isSoft() const { return name == "soft"; }
  // The label depends on each profile's image (not only on the geometry).
  bool perProfile() const { return name == "visible"; }
};

const std::vector<std::string>& labelPolicyNames();

// How label values are numbered: vessel voxels take 1, or their kind's class (datasets labelled
// by kind); the ignore label is one above every vessel value (nnU-Net's rule).
struct LabelNumbering {
  bool by_kind = false;
  std::uint8_t ignore_value = 2;
};

// The visible policy's evidence: the profile's noise-free image minus the same without vessels
// (signed so that vessels are positive), and the noise σ over vessel-free voxels.
struct VisibilityEvidence {
  const Volume<float>* contrast = nullptr;
  double noise_sigma = 0;
};

struct Label {
  Volume<std::uint8_t> values;  // every policy but soft
  Volume<float> soft;           // soft
};

// The label of `gt` (clean or warped) under the policy. `evidence` is needed by `visible` only;
// without it (no profile) every mask voxel with some partial volume is visible.
Label makeLabel(const LabelPolicy& p, const GroundTruthVolumes& gt, const LabelNumbering& n, const VisibilityEvidence* evidence = nullptr);

// The fraction of the tree's centreline length (sampled every quarter of the smallest voxel
// edge) that lands on vessel-labelled voxels, and on ignore-labelled ones, by calibre: radius bins
// in voxels (the smallest edge). For soft labels the mean label value along the centreline.
nlohmann::ordered_json labelLengthKept(const Label& label, const LabelPolicy& p, const LabelNumbering& n, const VascularTree& tree);
// The same on label values held elsewhere (`values`, or `soft` for the soft policy): the binary
// label is the mask itself and needs no copy.
nlohmann::ordered_json labelLengthKept(const Volume<std::uint8_t>* values, const Volume<float>* soft, const LabelPolicy& p, const LabelNumbering& n,
                                       const VascularTree& tree);

}  // namespace angiosynth
