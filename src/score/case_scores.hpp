#pragma once
// Scoring a segmentation against a truth (the stage's front door): a generated sample's exact
// truth, a dataset case's training label or exact mask, or any NIfTI annotation. `ScoreOptions`
// in, `scoreCase` runs every registered metric (score/metric.hpp), `CaseScores` out, with its
// own JSON form. Every metric's definition, connectivity and empty-mask convention is written
// into that JSON, and so is what the truth was.
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "score/label_schemes.hpp"

namespace angiosynth {

enum class ScoreConventions {
  Default,  // 6-neighbour borders, null for a surface distance when one mask is empty, Dice 1 when both are
  TopCoW,   // the TopCoW challenge's: 26-neighbour borders, 90 mm when one mask is empty, 0 for every ratio of empty masks
};

// Grids agree when every corner voxel's centre lies within this many voxels (of the smallest
// edge) under the two files' affines: float32 headers and qform/sform rounding stay far below
// it, a shift or flip of a voxel far above.
constexpr double kDefaultGridToleranceVoxels = 0.01;

struct ScoreOptions {
  std::optional<double> tolerance_mm;  // NSD's τ; unset: the smallest voxel edge
  ScoreConventions conventions = ScoreConventions::Default;
  std::vector<double> bins_voxels{0, 0.5, 1, 2, 4};  // calibre bins: lower edges, radius in voxels
  std::vector<double> bins_mm;                       // calibre bins in mm (none unless given)
  // Boundary IoU's band width d; unset: 2 % of the image diagonal (Cheng et al. 2021), at least a voxel.
  std::optional<double> boundary_width_mm;
  double grid_tolerance_voxels = kDefaultGridToleranceVoxels;
  // Label names and challenge metrics for multi-class labels (TopCoW 2024, TopBrain 2025).
  std::optional<LabelScheme> scheme;
  std::uint64_t memory_limit = 0;
  // HD95 and HD of a class or mask absent from one side under TopCoW's conventions.
  double missingDistanceMm() const { return scheme ? scheme->missing_distance_mm : 90.0; }
  // What makes these options unusable ("" when none): bins must be finite, non-negative and
  // increasing; widths and tolerances positive and finite.
  std::string invalid() const;
};

// The truth of one case. Only `mask` is required; each other file adds the metrics that need it.
struct TruthFiles {
  // Voxels > 0 are vessel (except `ignore_value`); its values are the classes when it is labelled.
  std::filesystem::path mask;
  std::filesystem::path centerline, radius;  // the exact centreline and the radius along it
  std::filesystem::path edges, keypoints;    // the generating graph (nodes.csv beside edges) and its key points
  std::filesystem::path classes;             // the kind of each vessel voxel, when not the mask's own values
  std::filesystem::path distractors;         // what the scored image shows that is not vessel (a degraded image's distractor label)
  std::map<int, std::string> legend;         // names of the class values (1 artery, 2 vein, …)
  std::optional<int> ignore_value;           // voxels of this value in `mask` count neither way (nnU-Net's ignore label)
  std::string name;                          // how the output names the truth (a file or directory)
  std::string what;                          // what it is: "the exact mask …", "the training label …"
};
// The legend of the classes volume from a sample.json ({"1": "artery", …}; background left out).
std::map<int, std::string> classLegend(const nlohmann::ordered_json& sample);
std::map<int, std::string> classLegend(const std::filesystem::path& sample_json);

// The files of a sample directory `generate` wrote (mask.nii.gz, centerline.nii.gz, …).
TruthFiles sampleTruth(const std::filesystem::path& sample_dir);
// A plain annotation: a NIfTI volume, binary or labelled, with whatever else is given.
TruthFiles annotationTruth(const std::filesystem::path& mask);

struct ScoreMetric;

// The scores of one case: each metric's block, and its headline numbers typed.
struct CaseScores {
  std::string prediction, truth;  // as the results name them
  std::string truth_what;         // what the truth is
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

// Scores PRED (a NIfTI; voxels > 0 are vessel, its values classes when labelled) against the
// truth; the grids must agree.
CaseScores scoreCase(const std::filesystem::path& pred, const TruthFiles& truth, const ScoreOptions& opt);

}  // namespace angiosynth
