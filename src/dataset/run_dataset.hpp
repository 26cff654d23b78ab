#pragma once
// Generating, finalizing and verifying an nnU-Net v2 raw dataset:
//   DatasetNNN_Name/imagesTr/<id>_0000.nii.gz    the degraded image (channel 0)
//   DatasetNNN_Name/labelsTr/<id>.nii.gz         the vessel mask (0 background, 1 vessel)
//   DatasetNNN_Name/groundtruth/<id>/            centreline, radius, instances, key points, graphs,
//                                                clean image, sample.json
//   DatasetNNN_Name/groundtruth/<id>.json        resolved parameters, seed, profile, statistics
//   DatasetNNN_Name/manifest/<part>.jsonl        one line per finished sample, per process
//   DatasetNNN_Name/manifest.jsonl, dataset.json, provenance.json   (finalize)
// Files are written in a staging directory of this process (.staging/<host>-<pid>/, so
// concurrent shards never share one) and renamed into place; the manifest line comes last, so an
// entry always means complete files.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "dataset/spec.hpp"
#include "pipeline/generate_sample.hpp"

namespace angiosynth {

// Which indices this process makes: [begin, end) ∩ {i : i mod shards = shard}.
struct DatasetSelection {
  std::int64_t begin = 0, end = 0;
  std::int64_t shard = 0, shards = 1;
  std::string part = "all";  // manifest part name: all, index-I, range-A-B, shard-K-of-M
  std::vector<std::int64_t> indices() const;
};

struct DatasetRunOptions {
  bool resume = false;              // skip samples whose manifest entry verifies
  bool regenerate_changed = false;  // with resume: accept a changed spec, redo the samples it changes
  std::uint64_t memory_limit = 0;
  int samples_in_flight = 0;  // 0: one per thread, fewer if memory is short
  std::string command_line;
  // Called after each sample (under a lock) with its manifest entry, samples done and total.
  std::function<void(const nlohmann::json& entry, std::int64_t done, std::int64_t total)> on_sample;
};

struct DatasetRunReport {
  std::int64_t generated = 0, skipped = 0, failed = 0;
  int in_flight = 1;
  std::filesystem::path dir;
};

DatasetRunReport runDataset(const DatasetSpec& spec, const std::filesystem::path& out_parent, const DatasetSelection& sel,
                            const DatasetRunOptions& opt);

// Sample `index` of a dataset made in memory, channel for channel what `runDataset` writes for it
// (the Python module's Spec[i]): the image of imagesTr is capture's volume `image_role`, the
// label of labelsTr `label_role`.
struct DatasetSampleInMemory {
  ResolvedSample resolved;
  SampleSummary summary;
  SampleCapture capture;
  std::string image_role, label_role;
};
DatasetSampleInMemory datasetSampleInMemory(const DatasetSpec& spec, std::int64_t index, std::uint64_t memory_limit,
                                            const std::function<bool()>& cancelled = {});

struct DatasetCheck {
  std::int64_t samples = 0, ok = 0;
  std::vector<std::string> problems;  // "missing <id>", "failed <id>: …", "corrupt <id>: <file>"
  std::vector<std::string> warnings;  // manifest lines skipped as invalid or torn
};

// Merges the manifest parts into manifest.jsonl and writes dataset.json and provenance.json.
DatasetCheck finalizeDataset(const std::filesystem::path& dataset_dir);
// Re-hashes every file of every sample against the manifests.
DatasetCheck verifyDataset(const std::filesystem::path& dataset_dir);

}  // namespace angiosynth
