#pragma once
// What the subcommands share: threads, seeds, progress on a terminal, the memory limit.
#include <CLI/CLI.hpp>

#include <cstdint>
#include <filesystem>
#include <utility>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "grow/common/growth_report.hpp"

namespace angiosynth::cli {

struct CommonOptions {
  int threads = 0;              // 0: all cores
  double memory_limit_gib = 0;  // 0: 75 % of physical memory
  bool quiet = false;
  std::string vascusynth_unit = "cm";
  bool vascusynth_rules = false;
};

// Commands that read VascuSynth parameter files also take their length unit.
enum class CommonInputs { Plain, WithVascuSynthFiles };
void addCommonOptions(CLI::App& cmd, CommonOptions& o, CommonInputs inputs = CommonInputs::Plain);
// Applies --threads for the lifetime of the returned object.
std::shared_ptr<void> limitThreads(int threads);
std::uint64_t memoryLimit(const CommonOptions& o);
// "warning: …" lines on stderr, the first `shown` of them, then how many more `where` holds.
void printWarnings(const std::vector<std::string>& warnings, const std::string& where, std::size_t shown = 12);
// A seed when none was given: fresh entropy, recorded in sample.json so the run can be repeated.
std::uint64_t freshSeed();
// Progress line on stderr when it is a terminal (and not --quiet); empty function otherwise.
ProgressFn progressPrinter(const CommonOptions& o, const std::string& label);
std::string commandLine(int argc, char** argv);
// The graph file of an INPUT that is a sample directory (its edges.csv, nodes.csv beside it) or a
// graph file (.csv, .gxl, .vtp, .swc, .cco); InputError when there is none.
std::filesystem::path graphOfInput(const std::string& input);
// A whole number >= 0 given for `what` (--index, --shard K), else InputError.
std::int64_t parseIndex(const std::string& text, const std::string& what);
// SLURM_ARRAY_TASK_ID (Slurm job arrays) or JOB_COMPLETION_INDEX (Kubernetes Indexed Jobs).
std::int64_t indexFromEnvironment(const std::string& what);
// --shard K/M (K from 0; auto/M takes K from the environment): {K, M}, 0 <= K < M.
std::pair<std::int64_t, std::int64_t> parseShard(const std::string& text);
// Command-line numbers: finite and within [lo, hi] (CLI11's Range lets NaN through).
CLI::Validator finiteIn(double lo, double hi);

}  // namespace angiosynth::cli
