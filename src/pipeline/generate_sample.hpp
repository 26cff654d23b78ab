#pragma once
// One sample through the pipeline: scenario → domain → growth → graph files and sample.json.
#include <cstdint>
#include <functional>
#include <stdexcept>
#include <filesystem>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "raster/volume.hpp"

#include "degrade/profile.hpp"
#include "grow/common/growth_report.hpp"
#include "grow/method.hpp"
#include "config/scenario.hpp"
#include "pipeline/vascusynth_layout.hpp"
#include "pipeline/volume_outputs.hpp"

namespace angiosynth {

struct SampleRequest {
  const Scenario* scenario = nullptr;
  std::uint64_t seed = 1;
  std::string gxl_dialect = "gxl";             // "gxl" or "vascusynth"
  std::optional<VascuSynthLayout> vascusynth;  // VascuSynth's own directory layout instead of angiosynth's
  std::string graph_id = "tree";
  std::string command_line;
  std::uint64_t memory_limit = 0;
  nlohmann::ordered_json extra;  // more resolved parameters for sample.json
  ProgressFn progress;
  std::uint64_t sample = 0;  // index within a dataset (part of every random stream)
  // Degradation profiles overriding the parameter file's [degrade] profiles when set.
  std::optional<std::vector<Profile>> profiles;
  bool record_timing = true;  // false: sample.json depends on seed and parameters only
  // The kinds in class-label order (1, 2, ...), when a dataset fixes them; empty: artery 1, vein 2.
  std::vector<std::string> class_kinds;
  // The Python module's samples: every volume, the forest and warped trees kept in memory, and
  // with write_files false nothing written (the sidecar is made all the same).
  SampleCapture* capture = nullptr;
  bool write_files = true;
  // Join the parts grown into this directory (growSamplePart) instead of growing the tree.
  std::optional<std::filesystem::path> parts_dir;
  // Polled at growth's progress points and between stages: true stops the sample with Cancelled.
  std::function<bool()> cancelled;
};

// Thrown when SampleRequest::cancelled asks the sample to stop.
struct Cancelled : std::runtime_error {
  Cancelled() : std::runtime_error("cancelled") {}
};

// What a sample made: the numbers a command reports, and its sidecar.
struct SampleSummary {
  std::int64_t terminals = 0;
  double total_volume_mm3 = 0;
  std::int64_t intersecting_pairs = 0;  // segment capsules that overlap, more than two segments apart
  double grow_seconds = 0;
  std::vector<std::string> warnings;     // what a user must read before using the files (a [mesh] surface not as asked)
  std::optional<VolumeGrid> image_grid;  // with volumes: their grid
  std::string image_grid_rule;           // and how it follows from the map (sample.json units.image_grid)
  nlohmann::ordered_json sidecar;        // sample.json as written
  // The file written for `role` ("image", "mask", "image_cta", …), relative to the sample's directory.
  std::filesystem::path file(const std::string& role) const;
  bool wrote(const std::string& role) const;
};

// Writes the sample's files and its sample.json into `dir`.
SampleSummary generateSample(const SampleRequest& request, const std::filesystem::path& dir);

// One task of a tree grown in parts ([tree] parts): grows part `index` of the request's sample
// into its file in `dir` (created if missing), or keeps the file a finished earlier run left.
// A later generateSample with parts_dir = dir joins them into the sample.
PartTaskSummary growSamplePart(const SampleRequest& request, int index, const std::filesystem::path& dir);

// Reads and checks everything a sample needs before growth (maps, masks, profiles, volume sizes,
// feasibility of the growth), writing nothing: so a batch can refuse a bad input before its first
// sample is written.
void checkSampleInputs(const Scenario& sc, std::uint64_t memory_limit);

// The resolved parameters of a scenario with their units, as recorded in sample.json.
nlohmann::ordered_json describeParameters(const Scenario& sc);

}  // namespace angiosynth
