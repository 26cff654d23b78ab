#pragma once
// Exact squared Euclidean distance transform (Felzenszwalb & Huttenlocher's lower envelope of
// parabolas, separable, O(n) per line, lines in parallel), with a spacing per axis.
#include <array>
#include <vector>

namespace angiosynth {

constexpr double kFarSquared = 1e20;  // "no site": larger than any squared distance on a grid

// In place on an n[0] × n[1] × n[2] grid (x fastest): g holds 0 at sites and kFarSquared
// elsewhere; afterwards the squared distance from each voxel centre to the nearest site, axis a
// counting h[a] per voxel. Only the first `axes` axes are swept (2: a one-slice grid).
void squaredDistances(std::vector<double>& g, const std::array<int, 3>& n, const std::array<double, 3>& h, int axes = 3);

}  // namespace angiosynth
