#pragma once
// DemandMap::segmentClear with each voxel's Chebyshev distance to the nearest zero-demand voxel:
// a segment that stays within that distance of its start crosses no obstacle, and is passed
// without walking its voxels. Growth asks this for every trial bifurcation, where most segments
// are short and far from obstacles. The same answers as the map's.
#include <cstdint>
#include <vector>

#include "core/vec3.hpp"
#include "domain/demand_map.hpp"

namespace angiosynth {

class ClearPaths {
 public:
  // Keeps a reference to `map`, whose demand must not change while this is in use.
  explicit ClearPaths(const DemandMap& map);
  bool segmentClear(const Vec3& a_mm, const Vec3& b_mm) const;
  const DemandMap& map() const { return map_; }

 private:
  const DemandMap& map_;
  // Chessboard distance (voxels, at most 255) to the nearest zero-demand voxel, on a grid padded
  // by one voxel on every side; empty when the map has no such voxel.
  std::vector<std::uint8_t> clearance_;
  std::int64_t stride_[3] = {0, 0, 0};
};

}  // namespace angiosynth
