#pragma once
// The training label of a sample under its label policy ([image] label_policy): for the clean
// image and, where it differs (a warp, or the visible policy), for each degraded image.
#include <nlohmann/json.hpp>

#include "degrade/degrade.hpp"
#include "pipeline/volume_files.hpp"
#include "raster/label_policy.hpp"

namespace angiosynth {

// The label channel of `label` named role ("label" or "label_<profile>").
Channel labelChannel(const Label& label, const LabelPolicy& p, const std::string& role);

// The visible policy's evidence for one degraded image: the profile run again without its noise
// effects (every draw kept), with and without the vessels; contrast = their difference, signed so
// that vessels are positive; σ = the root mean square of (degraded − noise-free) over the voxels
// without vessel (`fraction` == 0, in the degraded image's space). Deterministic for any threads.
struct ProfileVisibility {
  Volume<float> contrast;
  double noise_sigma = 0;
};
ProfileVisibility profileVisibility(const Profile& profile, const DegradeInput& in, const Volume<float>& degraded, const Volume<float>& fraction);

// Extra bytes per voxel the label policy needs while a profile runs (its label, and for visible
// the noise-free runs and their images).
std::uint64_t labelBytesPerVoxel(const LabelPolicy& p);

}  // namespace angiosynth
