#pragma once
// Hollow vessels (Lázaro 2011: printable vessel walls): the lumen (the vessels' own surface) and
// the outer wall (each vessel thickened by its wall), both built by the tube mesher with every
// end of the tree open in its plane, the lumen turned inside out, and each end's two loops
// joined by a flat ring. One closed surface per tree bounds the wall; with k open ends it has
// genus k − 1, and the lumen inside it runs from the inlet to every outlet.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "core/vascular_tree.hpp"
#include "mesh/tube_surface.hpp"

namespace angiosynth {

struct WallThickness {
  double constant_mm = 0;  // the same thickness everywhere, or
  double ratio = 0;        // a share of each vessel's radius, or
  bool from_tree = false;  // each vessel's own (VascularTree::wall_start, wall: linear along it)
  bool any() const { return constant_mm > 0 || ratio > 0 || from_tree; }
  // The thickness at a vessel's end of radius r whose own wall (from_tree) is w.
  double at(double r, double w) const { return from_tree ? w : constant_mm > 0 ? constant_mm : ratio * r; }
};

struct HollowWallReport {
  TubeSurfaceReport outer, lumen;
  std::int64_t rings = 0;  // ends joined
  // Ends (indices into the options' ends) one side could not open (a vessel ending against
  // another): the other side is capped flat there and the lumen ends.
  std::vector<std::int32_t> not_joined;
};

// The wall's surface: its outer side, the lumen (oriented into it, i.e. out of the wall), and a
// ring at each end (face k + 1 of end k, the sides face 0). `options.ends` must list every end
// of the tree (openEnds); they stay open. Throws InputError when a vessel has no wall thickness.
SurfaceMesh hollowWall(const VascularTree& tree, const TubeSurfaceOptions& options, const WallThickness& wall, HollowWallReport* report = nullptr,
                       const std::function<void(std::int64_t done, std::int64_t total)>& progress = {});

}  // namespace angiosynth
