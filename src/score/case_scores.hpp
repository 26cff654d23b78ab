#pragma once
// Scoring a segmentation against a generated sample's exact truth (the stage's front door):
// `ScoreOptions` in, `scoreCase` runs every registered metric (score/metric.hpp), `CaseScores`
// out, with its own JSON form. Every metric's definition, connectivity and empty-mask convention
// is written into that JSON.
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace angiosynth {

enum class ScoreConventions {
  Default,  // 6-neighbour borders, null for a surface distance when one mask is empty, Dice 1 when both are
  TopCoW,   // the TopCoW challenge's: 26-neighbour borders, 90 mm when one mask is empty, Dice 0 when both are
};

struct ScoreOptions {
  std::optional<double> tolerance_mm;  // NSD's τ; unset: the smallest voxel edge
  ScoreConventions conventions = ScoreConventions::Default;
  std::vector<double> bins_voxels{0, 0.5, 1, 2, 4};  // calibre bins: lower edges, radius in voxels
  std::vector<double> bins_mm;                       // calibre bins in mm (none unless given)
  // Boundary IoU's band width d; unset: 2 % of the image diagonal (Cheng et al. 2021), at least a voxel.
  std::optional<double> boundary_width_mm;
  std::uint64_t memory_limit = 0;
  // What makes these options unusable ("" when none): bins must be finite, non-negative and
  // increasing; widths and tolerances positive and finite.
  std::string invalid() const;
};

// The truth of one case: its mask, exact centreline and radius volumes, and its graph's edges
// file (with nodes beside it; empty: no vessel scores).
struct TruthFiles {
  std::filesystem::path mask, centerline, radius, edges, keypoints;  // edges, keypoints: optional
  std::string name;                                                  // how the output names the truth
  // Optional: the kind of each mask voxel and the legend of its values (1 artery, 2 vein, …).
  std::filesystem::path classes;
  std::map<int, std::string> legend;
};
// The legend of the classes volume from a sample.json ({"1": "artery", …}; background left out).
std::map<int, std::string> classLegend(const nlohmann::ordered_json& sample);
std::map<int, std::string> classLegend(const std::filesystem::path& sample_json);

// The files of a sample directory `generate` wrote (mask.nii.gz, centerline.nii.gz, …).
TruthFiles sampleTruth(const std::filesystem::path& sample_dir);

struct ScoreMetric;

// The scores of one case: each metric's block, and its headline numbers typed.
struct CaseScores {
  std::string prediction, truth;  // as the results name them
  ScoreConventions conventions = ScoreConventions::Default;
  struct Block {
    const ScoreMetric* metric;
    nlohmann::ordered_json detail;                // the metric's block
    std::vector<std::optional<double>> headline;  // its headline columns (unset: undefined or not computed)
  };
  std::vector<Block> blocks;  // every registered metric that applied, in the registry's order

  // A headline number by its CSV column (unset: undefined, not computed or no such column).
  std::optional<double> headline(const std::string& column) const;
  // The results file: prediction, truth, conventions, each block, the definitions.
  nlohmann::ordered_json toJson() const;
};

// Every headline column, in the registry's order (the CSV's columns after `case`).
std::vector<std::string> headlineColumns();

// Scores PRED (a NIfTI; voxels > 0 are vessel) against the truth; the grids must agree.
CaseScores scoreCase(const std::filesystem::path& pred, const TruthFiles& truth, const ScoreOptions& opt);

}  // namespace angiosynth
