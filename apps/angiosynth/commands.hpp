#pragma once
#include <CLI/CLI.hpp>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "cli_support.hpp"
#include "config/image_settings.hpp"
#include "config/mesh_settings.hpp"
#include "config/scenario.hpp"
#include "setting_flags.hpp"
#include "score/case_scores.hpp"
#include "segment/segment.hpp"

namespace angiosynth::cli {

struct GenerateArgs {
  std::string params;
  std::string out;
  std::optional<std::uint64_t> seed;
  SettingOverrides<ImageParameters> image;  // [image] settings given as flags
  SettingOverrides<Scenario> output;        // [output] settings given as flags
  bool force = false;
  std::vector<std::string> profiles;
  bool no_profiles = false;
  // A tree grown in parts ([tree] parts): one part as a task, or the join of all of them.
  int part = -1;
  bool join = false;
  std::string parts_dir;
  CommonOptions common;
};
CLI::App* addGenerate(CLI::App& app, GenerateArgs& a);
int runGenerate(const GenerateArgs& a, const std::string& command_line);

struct VascuSynthArgs {
  std::string param_list, name_list;
  double output_voxel_width = 0;
  std::vector<std::string> noise_files;
  std::string slices = "jpg";
  CommonOptions common;
};
CLI::App* addVascuSynth(CLI::App& app, VascuSynthArgs& a);
int runVascuSynth(const VascuSynthArgs& a, const std::string& command_line);

struct ParamsArgs {
  std::string method;
};
CLI::App* addParams(CLI::App& app, ParamsArgs& a);
int runParams(const ParamsArgs& a);

struct InitArgs {
  std::vector<std::string> args;  // [METHOD] FILE
};
CLI::App* addInit(CLI::App& app, InitArgs& a);
int runInit(const InitArgs& a);

struct DatasetArgs {
  std::string spec, out, dir;
  std::string index, range, shard;
  std::vector<std::string> set;  // key=value overrides of the spec
  bool resume = false;
  bool regenerate_changed = false;
  int in_flight = 0;
  CommonOptions common;
  CLI::App* describe = nullptr;
  CLI::App* finalize = nullptr;
  CLI::App* verify = nullptr;
};
CLI::App* addDataset(CLI::App& app, DatasetArgs& a);
int runDatasetCommand(const DatasetArgs& a, const std::string& command_line);

struct BenchmarkArgs {
  std::string spec, out, shard;
  std::vector<std::string> predictions;  // NAME=DIR
  std::vector<std::string> set;          // key=value for every rung
  std::vector<std::string> ladders;      // run these only
  bool resume = false, regenerate_changed = false;
  CommonOptions common;
};
CLI::App* addBenchmark(CLI::App& app, BenchmarkArgs& a);
int runBenchmarkCommand(const BenchmarkArgs& a, const std::string& command_line);

struct StatsArgs {
  std::string input, out, group;
  std::vector<double> bands;
  std::vector<std::string> compare;
  bool force = false;
  CommonOptions common;
};
CLI::App* addStats(CLI::App& app, StatsArgs& a);
int runStats(const StatsArgs& a);

struct SegmentArgs {
  std::string image, out, response;
  SegmentOptions options;
  bool dark = false, force = false;
  std::optional<double> threshold;
  CommonOptions common;
};
CLI::App* addSegment(CLI::App& app, SegmentArgs& a);
int runSegment(SegmentArgs a);

struct ScoreArgs {
  std::string prediction, truth, out, csv, class_csv;
  std::string centreline, radius, graph, legend, label_scheme;                 // with a plain annotation as TRUTH
  std::string dataset, predictions, case_id, splits, truth_kind = "training";  // --dataset mode
  std::vector<std::string> cases;
  int fold = -1;
  std::string plot;
  ScoreOptions options;  // tolerance, band width and grid tolerance from their flags
  bool topcow = false, force = false;
  std::vector<double> bins_voxels, bins_mm;
  CommonOptions common;
};
CLI::App* addScore(CLI::App& app, ScoreArgs& a);
int runScore(const ScoreArgs& a);

struct MeshArgs {
  std::string input, out;
  MeshParameters mesh;  // every setting of [mesh], filled by its flag (config/mesh_settings.cpp)
  bool force = false;
  CommonOptions common;
};
CLI::App* addMesh(CLI::App& app, MeshArgs& a);
int runMesh(const MeshArgs& a, const std::string& command_line);

struct RasterizeArgs {
  std::string input, out;
  ImageParameters image;  // the [image] settings with a flag here (cmd_rasterize.cpp); the rest: the sample's
  int task = -1, tasks = 0;
  bool pyramid = false;
  SettingFlagList<ImageParameters> flags;  // which were given
  CommonOptions common;
};
CLI::App* addRasterize(CLI::App& app, RasterizeArgs& a);
int runRasterize(const RasterizeArgs& a, const std::string& command_line);

struct PlotCalibreArgs {
  std::string out;
  std::vector<std::string> scores;
  std::vector<std::string> labels;  // the legend's names (default: each file's name)
  bool force = false;
};
CLI::App* addPlotCalibre(CLI::App& app, PlotCalibreArgs& a);
int runPlotCalibre(const PlotCalibreArgs& a);

}  // namespace angiosynth::cli
