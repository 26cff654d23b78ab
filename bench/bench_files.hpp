#pragma once
// What the per-file growth benchmarks share: `FILE.toml ... [--threads T]` on the command line,
// and each file's forest grown 5 times with the fastest run kept. The final crossing/overlap
// count is a check of the result, not growth, so its time is reported apart.
#include <tbb/global_control.h>

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "config/scenario.hpp"

namespace angiosynth::bench {

struct FileArgs {
  std::vector<std::string> files;
  std::unique_ptr<tbb::global_control> threads;
};

// Takes `NAME VALUE` out of argv (its last occurrence wins): VALUE, or `fallback` if absent.
// The arguments left are in `rest` (the program name first), for parseFileArgs.
inline double takeOption(int argc, char** argv, const char* name, double fallback, std::vector<char*>& rest) {
  rest.clear();
  for (int i = 0; i < argc; ++i) {
    if (!std::strcmp(argv[i], name) && i + 1 < argc)
      fallback = std::atof(argv[++i]);
    else
      rest.push_back(argv[i]);
  }
  return fallback;
}

inline FileArgs parseFileArgs(int argc, char** argv) {
  FileArgs a;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--threads") && i + 1 < argc)
      a.threads = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, std::atoi(argv[++i]));
    else
      a.files.push_back(argv[i]);
  }
  return a;
}

inline double millisecondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

struct TimedGrowth {
  Forest forest;
  nlohmann::ordered_json stats;  // the fastest run's statistics
  double grow_ms = 1e300;
  double check_ms = 0;
};

// Seed: the file's, else 1.
inline TimedGrowth bestOfFive(const std::string& file) {
  const auto sc = readTomlParameters(file);
  const auto prepared = sc.growth->prepare(std::uint64_t(1) << 40);
  TimedGrowth best;
  for (int run = 0; run < 5; ++run) {
    GrowthReport report;
    const auto t0 = std::chrono::steady_clock::now();
    Forest forest = prepared->grow(sc.seed.value_or(1), 0, report, {});
    nlohmann::ordered_json stats = nlohmann::ordered_json::object();
    prepared->addStatistics(report, stats);
    const double check = stats["timing_seconds"].value("crossing_check", 0.0) * 1e3;
    const double ms = millisecondsSince(t0) - check;
    if (ms < best.grow_ms) best = TimedGrowth{std::move(forest), std::move(stats), ms, check};
  }
  return best;
}

}  // namespace angiosynth::bench
