#pragma once
// Bifurcations and endpoints: found in a prediction's skeleton, known exactly in the truth's
// graph (keypoints.csv), and matched one to one within a tolerance.
#include <filesystem>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/vec3.hpp"
#include "raster/volume.hpp"

namespace angiosynth {

struct KeyPoint {
  Vec3 mm;
  double radius = 0;  // the truth's local radius (mm); 0 for predicted points
};

struct KeyPoints {
  std::vector<KeyPoint> bifurcations, endpoints;
};

// Skeleton voxels with one 26-neighbour are endpoints; 26-connected clusters of voxels with three
// or more are one bifurcation each, at the cluster's centroid. Positions in the grid's mm frame.
KeyPoints skeletonKeyPoints(const Volume<std::uint8_t>& skeleton);

// The truth's bifurcations and endpoints (terminals and roots) from keypoints.csv, those inside
// the grid; with their radii.
KeyPoints truthKeyPoints(const std::filesystem::path& keypoints_csv, const VolumeGrid& grid);

// One-to-one matching, closest pairs first: a truth point and a predicted point match when they
// lie within max(min_tolerance_mm, the truth's local radius). Precision, recall and F1.
nlohmann::ordered_json matchKeyPoints(const std::vector<KeyPoint>& predicted, const std::vector<KeyPoint>& truth, double min_tolerance_mm);

}  // namespace angiosynth
