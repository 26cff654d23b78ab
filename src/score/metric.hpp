#pragma once
// A score metric: one block of a case's results, computed from the prediction and the truth,
// with its definition and the headline numbers a dataset summary and the CSV carry. Each metric
// lives in its own file under score/metrics/ and is listed once in score/metric_registry.cpp;
// `angiosynth score`, its CSV columns, the dataset summary and the docs read that list.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "io/nifti_reader.hpp"
#include "raster/volume.hpp"
#include "score/case_scores.hpp"

namespace angiosynth {

// What a metric reads: the prediction and the truth on one grid (checked), the truth's exact
// centreline and radius when it has them, the classes of both when labelled, and the skeletons,
// thinned once for every metric that asks.
class ScoringCase {
 public:
  ScoringCase(const ScoreOptions& options, const TruthFiles& files, const NiftiVolume& prediction_file, const NiftiVolume& truth_file,
              const Volume<float>* centreline, const Volume<float>* radius);
  const ScoreOptions& options;
  const TruthFiles& files;
  const NiftiVolume& prediction_file;  // as read: its values (labels by kind, if any) and affine
  const NiftiVolume& truth_file;
  const Volume<std::uint8_t> ignore;             // the truth's ignore-label voxels (none without one)
  const Volume<std::uint8_t> prediction, truth;  // voxels > 0, the ignore voxels left out of both
  const Volume<float>* centreline;               // the exact centreline and the radius along it (null: none)
  const Volume<float>* radius;
  const double voxel_mm;      // the smallest voxel edge
  const double tolerance_mm;  // NSD's τ
  bool topcow() const { return options.conventions == ScoreConventions::TopCoW; }
  const Volume<std::uint8_t>& predictionSkeleton() const;
  const Volume<std::uint8_t>& truthSkeleton() const;
  // The class of each truth voxel (0 elsewhere): the classes volume, else the labelled mask's own
  // values; null when the truth has no classes.
  const Volume<std::uint8_t>* truthClasses() const;
  // The prediction's values as classes (0 elsewhere, the ignore voxels left out).
  const Volume<std::uint8_t>& predictionClasses() const;
  // The prediction holds classes: whole numbers from 0 to 255, some above 1 (or the truth's only
  // class is 1).
  bool predictionLabelled() const;
  // The legend's name of a class value ("label N" when the legend lacks it).
  std::string className(int value) const;
  // Another volume of the truth (classes), read under the memory limit and checked to lie on its grid.
  NiftiVolume readTruthVolume(const std::filesystem::path& file, const char* what) const;

 private:
  mutable std::optional<Volume<std::uint8_t>> prediction_skeleton_, truth_skeleton_, truth_classes_, prediction_classes_;
  mutable bool classes_read_ = false;
};

// One headline number of a metric: the CSV column and, within the metric's block, the JSON
// pointer the number is read from (for a reader of the JSON).
struct HeadlineColumn {
  const char* column;
  const char* pointer;
};

struct ScoreMetric {
  const char* key;         // the block's name in the results
  const char* definition;  // how it is computed, written into every result
  std::vector<HeadlineColumn> headline;
  // The block, or null when the truth lacks what it needs (a graph, key points, classes).
  nlohmann::ordered_json (*compute)(const ScoringCase& c);
  // Optional: what the metric says of many cases together (class summaries, detection F1 over
  // cases, balanced accuracies), from each case's block (null where the case had none).
  nlohmann::ordered_json (*aggregate)(const std::vector<const nlohmann::ordered_json*>& blocks) = nullptr;
};

// Every metric, in the order of the results and of the CSV columns.
const std::vector<const ScoreMetric*>& scoreMetrics();
const ScoreMetric* findScoreMetric(const std::string& key);
// Markdown list of every metric and its headline columns (the docs).
std::string scoreMetricReference();

}  // namespace angiosynth
