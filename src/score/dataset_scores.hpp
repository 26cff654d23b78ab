#pragma once
// Scoring predictions for a whole generated dataset (nnU-Net layout): one row per case, then
// the mean, median and spread of every headline metric.
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "grow/common/growth_report.hpp"
#include "score/case_scores.hpp"

namespace angiosynth {

// The truth of case `id` of a dataset directory: the files of its profile's image (warped
// labels and graph when the profile warps), the mask from labelsTr when the dataset moved it
// there (binary labels).
TruthFiles datasetCaseTruth(const std::filesystem::path& dataset_dir, const std::string& id);

// Scores PREDICTIONS/<id>.nii.gz for every case of the dataset (a missing prediction is an
// error naming the case). `csv` receives one row per case and the summary rows.
nlohmann::ordered_json scoreDataset(const std::filesystem::path& dataset_dir, const std::filesystem::path& predictions, const ScoreOptions& opt,
                                    const ProgressFn& progress, std::string& csv);

// One CSV header and row of a case's headline numbers, in the same columns.
std::string scoreCsvHeader();
std::string scoreCsvRow(const std::string& name, const CaseScores& scores);

}  // namespace angiosynth
