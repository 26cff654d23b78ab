#pragma once
// Scoring a segmentation against a generated sample's exact truth: overlap, surface distances
// in mm, recall by vessel calibre from the exact centreline and radius, and vessels detected
// from the generating graph. Every metric's definition, connectivity and empty-mask convention
// is written into the result.
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "raster/volume.hpp"

namespace angiosynth {

struct ScoreOptions {
  double tolerance_mm = 0;                           // NSD's τ; 0: the smallest voxel edge
  bool topcow = false;                               // TopCoW's conventions (see surfaceScores)
  std::vector<double> bins_voxels{0, 0.5, 1, 2, 4};  // calibre bins: lower edges, radius in voxels
  std::vector<double> bins_mm;                       // calibre bins in mm (none unless given)
  std::uint64_t memory_limit = 0;
};

// A ratio, or null when its denominator is 0 (undefined): how every score states an empty case.
nlohmann::ordered_json ratio(double num, double den);

// Overlap of two binary volumes on one grid: tp, fp, fn, Dice, Jaccard, precision, recall.
nlohmann::ordered_json overlapScores(const Volume<std::uint8_t>& pred, const Volume<std::uint8_t>& truth, bool topcow);

// Border voxels: foreground voxels with a background neighbour (6 face neighbours; 26 with
// `all_neighbours`), voxels beyond the grid counting as background.
Volume<std::uint8_t> borderVoxels(const Volume<std::uint8_t>& v, bool all_neighbours);

// The distance (mm, between voxel centres, the grid's spacing per axis) from each border voxel
// of `from` to the nearest border voxel of `to`, in voxel order.
std::vector<double> directedBorderDistances(const Volume<std::uint8_t>& from_border, const Volume<std::uint8_t>& to_border);

// HD, HD95 (the larger of the two directed 95th percentiles, linear interpolation between order
// statistics as NumPy's default), ASSD, MASD and NSD at tolerance τ between the borders of two
// volumes. Empty masks: both empty give 0 mm and NSD 1; one empty gives null (TopCoW: 90 mm).
nlohmann::ordered_json surfaceScores(const Volume<std::uint8_t>& pred, const Volume<std::uint8_t>& truth, double tolerance_mm,
                                     bool topcow);

// clDice (Shit et al. 2021) from the two skeletons and masks: topology precision, sensitivity,
// their harmonic mean (null when a skeleton is empty).
nlohmann::ordered_json clDice(const Volume<std::uint8_t>& pred_skeleton, const Volume<std::uint8_t>& truth,
                              const Volume<std::uint8_t>& truth_skeleton, const Volume<std::uint8_t>& pred);

// 95th percentile, linear interpolation between order statistics (NumPy's default).
double percentile95(std::vector<double> values);

// The truth of one case: its mask, exact centreline and radius volumes, and its graph's edges
// file (with nodes beside it; empty: no vessel scores).
struct TruthFiles {
  std::filesystem::path mask, centerline, radius, edges, keypoints;  // edges, keypoints: optional
  std::string name;  // how the output names the truth
  // Optional: the kind of each mask voxel and the legend of its values (1 artery, 2 vein, …).
  std::filesystem::path classes;
  std::map<int, std::string> legend;
};
// The legend of the classes volume from a sample.json ({"1": "artery", …}; background left out).
std::map<int, std::string> classLegend(const nlohmann::ordered_json& sample);
std::map<int, std::string> classLegend(const std::filesystem::path& sample_json);

// The files of a sample directory `generate` wrote (mask.nii.gz, centerline.nii.gz, …).
TruthFiles sampleTruth(const std::filesystem::path& sample_dir);

// Scores PRED (a NIfTI; voxels > 0 are vessel) against the truth; the grids must agree.
nlohmann::ordered_json scoreCase(const std::filesystem::path& pred, const TruthFiles& truth, const ScoreOptions& opt);

}  // namespace angiosynth
