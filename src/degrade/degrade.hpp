#pragma once
// Runs a profile: the clean image of a sample through its effects, in order, each with its own
// random stream of (seed, sample, profile, effect), so the result is the same for any thread
// count and adding an effect does not change the draws of the others.
#include <memory>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "degrade/profile.hpp"
#include "degrade/warp.hpp"
#include "raster/ground_truth.hpp"

namespace angiosynth {

struct DegradeInput {
  const VascularTree* tree = nullptr;
  const GroundTruthVolumes* truth = nullptr;  // clean raster of `tree`
  std::uint64_t seed = 1, sample = 0;
  double background = 0, vessel = 255;  // defaults for profiles that do not set them
  std::string dtype = "uint8";
  // For the visible label's evidence: skip the noise effects (every draw stays as it is, so the
  // other effects do exactly what they do in the noisy run), and optionally image another
  // partial volume (all zero: the same scene without vessels).
  bool noise_free = false;
  const Volume<float>* fraction = nullptr;  // instead of truth->fraction
};

struct DegradedImage {
  std::string profile;
  Volume<float> image;  // intensities, before conversion to dtype
  double background = 0, vessel = 255;
  std::string dtype;
  nlohmann::ordered_json record;  // every drawn value, for sample.json
  // Set when the profile warps: labels and tree aligned with the warped image.
  std::optional<GroundTruthVolumes> labels;
  std::shared_ptr<VascularTree> tree;
  std::vector<std::int32_t> segment_origin;  // clean segment of each warped-tree segment
  std::shared_ptr<const BSplineWarp> warp;
  nlohmann::ordered_json seconds;  // time per effect (kept out of `record`)
  // Set when a distractor effect placed something: its kind per voxel (DistractorKind, 0 elsewhere),
  // aligned with the image; never a vessel voxel.
  std::optional<Volume<std::uint8_t>> distractors;
};

DegradedImage degradeImage(const Profile& profile, const DegradeInput& in);

// The dtype's representable range ([-inf, inf] for float32).
void dtypeRange(const std::string& dtype, double& lo, double& hi);

}  // namespace angiosynth
