#pragma once
// 3D thinning to a one-voxel skeleton by the algorithm of Lee, Kashyap and Chu (1994) in the
// order scikit-image's `skeletonize_3d` applies it (the first array axis, x here, outermost;
// borders taken W, E, S, N, U, B; candidates collected, then re-checked one by one), so
// skeleton-based scores (clDice) sit beside the published implementations.
#include <cstdint>

#include "raster/volume.hpp"

namespace angiosynth {

Volume<std::uint8_t> skeletonize(const Volume<std::uint8_t>& v);

}  // namespace angiosynth
