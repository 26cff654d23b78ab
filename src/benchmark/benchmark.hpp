#pragma once
// A benchmark: difficulty ladders over one dataset spec, each rung the dataset with one value
// replaced (noise, voxel size, tree size, modality …), every rung scored for the reference
// segmenters and for the user's own predictions, and a report to read. One front door:
// `BenchmarkSpec` (read from a benchmark file), `BenchmarkOptions`, `runBenchmark`,
// `BenchmarkSummary`.
//
// OUT/<ladder>/<rung>/DatasetNNN_Name/    the rung's dataset (resumable, shardable: `dataset`'s)
// OUT/<ladder>/<rung>/predictions/<method>/<case>.nii.gz   each baseline's masks
// OUT/<ladder>/<rung>/scores/<method>.json                  `score --dataset` results
// OUT/results.csv, OUT/benchmark.json, OUT/report.html      one row per rung and method
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "dataset/spec.hpp"
#include "score/dataset_scores.hpp"
#include "segment/segment.hpp"

namespace angiosynth {

struct BenchmarkLadder {
  std::string name;                 // its directory and its section of the report
  std::string title;                // the report's heading and axis ("Gaussian noise σ")
  std::string key;                  // the value swept (a spec override key)
  std::vector<std::string> values;  // TOML text of each rung's value
  std::vector<std::string> labels;  // how the report names each rung (default: the value)
  std::vector<SpecOverride> fixed;  // further values this ladder holds fixed
  int line = 0;
  std::string rungDir(std::size_t rung) const;                  // "00", "01", …
  std::vector<SpecOverride> overrides(std::size_t rung) const;  // fixed, then the rung's value
};

struct BenchmarkSpec {
  std::string file;  // the benchmark file, for errors and the report
  std::string text;  // its content (recorded in benchmark.json)
  std::string title, description;
  std::filesystem::path dataset;          // the base dataset spec (resolved beside the file)
  std::vector<SpecOverride> dataset_set;  // [benchmark] samples and [benchmark.set]: every rung's
  std::vector<std::string> methods;       // reference segmenters (angiosynth segment's methods)
  SegmentOptions segment;                 // their options (method aside)
  DatasetTruth truth = DatasetTruth::Exact;
  // Also each baseline with the threshold that maximises the rung's mean Dice against the truth
  // ("<method>-tuned"): an upper bound for any global threshold rule, not a method to deploy.
  bool tuned = false;
  std::vector<BenchmarkLadder> ladders;
};

// Reads and checks a benchmark file, every rung's dataset included: errors name the file and line.
// `set`: values every rung shares besides the file's (the command line's --set), applied last
// but for each ladder's own value.
BenchmarkSpec readBenchmarkSpec(const std::filesystem::path& file, const std::vector<SpecOverride>& set = {});
// Keeps only the ladders named (all when `names` is empty); an unknown name is an InputError
// naming the ladders there are.
void selectLadders(BenchmarkSpec& spec, const std::vector<std::string>& names);
// Rung `rung` of `ladder` as a dataset spec (the base with the ladder's overrides).
DatasetSpec rungDataset(const BenchmarkSpec& spec, const BenchmarkLadder& ladder, std::size_t rung);

// A user's method: predictions in DIR/<ladder>/<rung>/<case>.nii.gz.
struct BenchmarkPredictions {
  std::string name;
  std::filesystem::path dir;
};

struct BenchmarkOptions {
  bool resume = false;                 // continue in an OUT that holds an earlier run of this benchmark
  bool regenerate_changed = false;     // with resume: accept an edited spec, redo what it changes
  std::int64_t shard = 0, shards = 1;  // shards > 1: make this shard of every rung's samples only
  std::vector<BenchmarkPredictions> predictions;
  std::uint64_t memory_limit = 0;
  std::string command_line;
  std::function<void(const std::string& message)> progress;  // one line per step
};

// One rung and method: the means (and SDs) over the rung's cases.
struct BenchmarkRow {
  std::string ladder, rung, label, value, method;
  bool baseline = true;
  std::int64_t cases = 0;
  double dice = 0, dice_sd = 0, cldice = 0, cldice_sd = 0;
  double hd95_mm = 0, precision = 0, recall = 0, centreline_recall = 0, b0_error = 0;
  std::vector<double> calibre_lower, calibre_recall;         // recall over the rung's centreline voxels by radius bin (voxels); NaN: none
  double thin_recall = 0;                                    // of vessels thinner than a voxel in radius
  std::vector<std::pair<std::string, double>> class_recall;  // mean recall of each kind (with two kinds or more)
  double seconds_per_case = 0;                               // the segmenter's time (baselines)
  double tuned_fraction = 0;                                 // a tuned baseline's threshold, as a share of each case's response range (else NaN)
};

struct BenchmarkSummary {
  std::vector<BenchmarkRow> rows;
  std::int64_t samples_generated = 0, samples_skipped = 0, samples_failed = 0;
  std::int64_t cases_segmented = 0;
  bool scored = false;  // false for a shard: datasets only
  std::filesystem::path report, csv, json;
  double seconds = 0;
};

BenchmarkSummary runBenchmark(const BenchmarkSpec& spec, const std::filesystem::path& out, const BenchmarkOptions& options);

// The report: one HTML file with everything inline (SVG curves, PNG thumbnails as data URIs).
struct BenchmarkThumbnail {
  std::string ladder, rung;
  std::string png;  // the PNG's bytes
  std::string caption;
};
std::string benchmarkReportHtml(const BenchmarkSpec& spec, const BenchmarkSummary& summary, const std::vector<BenchmarkThumbnail>& thumbnails,
                                const std::string& command_line);
// results.csv: the scores only (no timing), so the same spec gives the same bytes.
std::string benchmarkCsv(const std::vector<BenchmarkRow>& rows);

}  // namespace angiosynth
