#pragma once
// Betti numbers of a binary volume: b0 connected pieces (foreground 26-connected), b2 cavities
// (background 6-connected pieces that do not reach the padded outside), b1 tunnels from the
// Euler characteristic of the union of closed voxel cubes (b1 = b0 + b2 − χ).
#include <array>
#include <cstdint>

#include "raster/volume.hpp"

namespace angiosynth {

struct Betti {
  std::int64_t b0 = 0, b1 = 0, b2 = 0;
  std::int64_t euler = 0;  // χ = b0 − b1 + b2
};

Betti bettiNumbers(const Volume<std::uint8_t>& v);

// Connected pieces of the voxels equal to `value` (26- or 6-connected), with a one-voxel border
// of background around the grid when `padded` (the outside counts as one background piece).
std::int64_t countComponents(const Volume<std::uint8_t>& v, std::uint8_t value, int connectivity, bool padded);

}  // namespace angiosynth
