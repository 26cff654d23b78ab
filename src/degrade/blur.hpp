#pragma once
// Separable Gaussian blur, shared by the blur effect and anything else that needs a PSF.
#include <vector>

#include "degrade/effect.hpp"

namespace angiosynth {

// Normalised sampled Gaussian of σ (voxels), half-width ceil(truncate·σ); {1} for σ = 0.
std::vector<float> gaussianKernel(double sigma_voxels, double truncate = 4);
// Blurs in place with σ per axis in mm; `scratch` (a volume on the same grid), when given, saves
// allocating one per call.
void gaussianBlur(Volume<float>& v, const Vec3& sigma_mm, double truncate = 4, Volume<float>* scratch = nullptr);

}  // namespace angiosynth
