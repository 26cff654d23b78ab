#include "cli_support.hpp"

#include <tbb/global_control.h>
#include <unistd.h>

#include <chrono>
#include <climits>
#include <cstdlib>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <random>

#include "core/error.hpp"
#include "core/memory.hpp"

namespace angiosynth::cli {

void addCommonOptions(CLI::App& cmd, CommonOptions& o, CommonInputs inputs) {
  cmd.add_option("--threads", o.threads, "worker threads (0 = all cores); outputs do not depend on it")->check(CLI::Range(0, 1024));
  cmd.add_option("--memory-limit", o.memory_limit_gib,
                 "refuse work whose estimated memory exceeds this many GiB, before allocating it (default: 75% of RAM)")
      ->check(finiteIn(0.0, 1e6));
  if (inputs == CommonInputs::WithVascuSynthFiles)
    cmd.add_option("--vascusynth-unit", o.vascusynth_unit,
                   "length unit of VOXEL_WIDTH in VascuSynth parameter files; flows and pressures follow the "
                   "coherent (length, g, s) system, i.e. CGS for cm")
        ->check(CLI::IsMember({"um", "mm", "cm", "m"}));
  if (inputs == CommonInputs::WithVascuSynthFiles)
    cmd.add_flag("--vascusynth-rules", o.vascusynth_rules,
                 "grow VascuSynth parameter files under VascuSynth's own constraints (no minimum length in radii, no final relaxation, "
                 "overlapping vessels allowed), as [tree] rules = \"vascusynth\" does in a .toml file");
  cmd.add_flag("--quiet", o.quiet, "no progress output");
}

std::shared_ptr<void> limitThreads(int threads) {
  if (threads <= 0) return nullptr;
  return std::make_shared<tbb::global_control>(tbb::global_control::max_allowed_parallelism, threads);
}

std::uint64_t memoryLimit(const CommonOptions& o) {
  return o.memory_limit_gib > 0 ? static_cast<std::uint64_t>(o.memory_limit_gib * double(1ULL << 30)) : defaultMemoryLimitBytes();
}

void printWarnings(const std::vector<std::string>& warnings, const std::string& where, std::size_t shown) {
  for (std::size_t k = 0; k < warnings.size() && k < shown; ++k) std::cerr << "warning: " << warnings[k] << "\n";
  if (warnings.size() > shown) std::cerr << "warning: " << warnings.size() - shown << " more in " << where << "\n";
}

std::uint64_t freshSeed() {
  std::random_device rd;
  const std::uint64_t s =
      (std::uint64_t(rd()) << 32) ^ rd() ^ static_cast<std::uint64_t>(std::chrono::steady_clock::now().time_since_epoch().count());
  return s & ((1ULL << 53) - 1);  // exact in JSON readers that use doubles
}

ProgressFn progressPrinter(const CommonOptions& o, const std::string& label) {
  if (o.quiet || !isatty(STDERR_FILENO)) return {};
  const auto start = std::chrono::steady_clock::now();
  return [label, start](std::int64_t done, std::int64_t total) {
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::fprintf(stderr, "\r%s: %lld / %lld terminals (%.1f s)%s", label.c_str(), static_cast<long long>(done), static_cast<long long>(total), s,
                 done >= total ? "\n" : "");
    std::fflush(stderr);
  };
}

CLI::Validator finiteIn(double lo, double hi) {
  return CLI::Validator(
      [lo, hi](std::string& text) -> std::string {
        double v = 0;
        std::size_t used = 0;
        try {
          v = std::stod(text, &used);
        } catch (const std::exception&) { used = 0; }
        if (used != text.size() || !std::isfinite(v) || v < lo || v > hi)
          return "'" + text + "' is not a finite number in [" + CLI::detail::to_string(lo) + ", " + CLI::detail::to_string(hi) + "]";
        return {};
      },
      "FINITE in [" + CLI::detail::to_string(lo) + ", " + CLI::detail::to_string(hi) + "]");
}

std::filesystem::path graphOfInput(const std::string& input) {
  const std::filesystem::path in(input);
  if (!std::filesystem::exists(in)) throw InputError(input, 0, "no such sample directory or graph file");
  const std::filesystem::path graph = std::filesystem::is_directory(in) ? in / "edges.csv" : in;
  if (!std::filesystem::exists(graph))
    throw InputError(graph.string(), 0, "no such file: a sample directory holds the nodes.csv and edges.csv angiosynth generate writes");
  return graph;
}

std::int64_t parseIndex(const std::string& text, const std::string& what) {
  std::size_t used = 0;
  long long v = -1;
  try {
    v = std::stoll(text, &used);
  } catch (const std::exception&) {}
  if (text.empty() || used != text.size() || v < 0)
    throw InputError("", 0, what + ": '" + text + "' is not a whole number in 0…" + std::to_string(LLONG_MAX));
  return v;
}

std::int64_t indexFromEnvironment(const std::string& what) {
  for (const char* var : {"SLURM_ARRAY_TASK_ID", "JOB_COMPLETION_INDEX"})
    if (const char* v = std::getenv(var)) return parseIndex(v, var);
  throw InputError("", 0, what + " auto: neither SLURM_ARRAY_TASK_ID nor JOB_COMPLETION_INDEX is set");
}

std::pair<std::int64_t, std::int64_t> parseShard(const std::string& text) {
  const auto slash = text.find('/');
  if (slash == std::string::npos) throw InputError("", 0, "--shard takes K/M (K from 0) or auto/M");
  const std::int64_t shards = parseIndex(text.substr(slash + 1), "--shard M");
  const std::string k = text.substr(0, slash);
  const std::int64_t shard = k == "auto" ? indexFromEnvironment("--shard") : parseIndex(k, "--shard K");
  if (shards < 1 || shard >= shards) throw InputError("", 0, "--shard K/M needs 0 <= K < M");
  return {shard, shards};
}

std::string commandLine(int argc, char** argv) {
  std::string s;
  for (int i = 0; i < argc; ++i) s += (i ? " " : "") + std::string(argv[i]);
  return s;
}

}  // namespace angiosynth::cli
