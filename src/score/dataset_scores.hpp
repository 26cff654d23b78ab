#pragma once
// Scoring predictions for a generated dataset (nnU-Net layout): the cases that have a prediction
// (all, a list, or one fold of nnU-Net's splits), each against the truth chosen, one row per
// case, then the mean, median and spread of every headline metric, and what each metric says
// over the cases together (class summaries, challenge rates).
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "grow/common/growth_report.hpp"
#include "score/case_scores.hpp"

namespace angiosynth {

// Which truth a dataset case is scored against.
enum class DatasetTruth {
  Training,  // labelsTr: the label the network was trained on, under the dataset's label policy (its ignore label respected)
  Exact,     // the exact mask (partial volume >= 0.5 or crossed by a centreline), whatever the policy
};
const char* datasetTruthName(DatasetTruth t);

struct DatasetScoreOptions {
  DatasetTruth truth = DatasetTruth::Training;
  std::vector<std::string> cases;  // score only these (empty: every case with a prediction)
  std::filesystem::path splits;    // nnU-Net's splits_final.json: with `fold`, its validation cases
  int fold = -1;
};

// The truth of case `id` of a dataset directory: the files of its profile's image (warped
// labels and graph when the profile warps).
TruthFiles datasetCaseTruth(const std::filesystem::path& dataset_dir, const std::string& id, DatasetTruth truth);

struct DatasetScores {
  nlohmann::ordered_json results;            // the results file
  std::string csv;                           // one row per case, then mean, median, sd
  std::string class_csv;                     // one row per class: its numbers over the cases (empty without classes)
  std::vector<std::string> scored, missing;  // cases scored; selected cases without a prediction
};

// Scores PREDICTIONS/<id>.nii.gz for the selected cases that have one; the others are reported
// as missing (an error only when no case has a prediction).
DatasetScores scoreDataset(const std::filesystem::path& dataset_dir, const std::filesystem::path& predictions, const ScoreOptions& opt,
                           const DatasetScoreOptions& select, const ProgressFn& progress);

// One CSV header and row of a case's headline numbers, in the same columns.
std::string scoreCsvHeader();
std::string scoreCsvRow(const std::string& name, const CaseScores& scores);

}  // namespace angiosynth
