// `angiosynth benchmark SPEC --out DIR`: difficulty ladders, baselines, scores and a report.
#include <iostream>
#include <tuple>

#include "benchmark/benchmark.hpp"
#include "commands.hpp"
#include "core/error.hpp"

namespace angiosynth::cli {

CLI::App* addBenchmark(CLI::App& app, BenchmarkArgs& a) {
  auto* c = app.add_subcommand("benchmark",
                               "difficulty ladders over a dataset spec: every rung generated, segmented by the reference segmenters and scored; "
                               "report.html (curves, thumbnails, tables), results.csv, benchmark.json");
  c->add_option("SPEC", a.spec, "benchmark file (.toml): [benchmark], [segment], [[ladder]] (docs/benchmark-ladders.md)")->required();
  c->add_option("--out", a.out, "the benchmark's directory")->required();
  c->add_option("--predictions", a.predictions,
                "NAME=DIR: your method's masks, DIR/<ladder>/<rung>/<case>.nii.gz, scored beside the baselines (repeatable)");
  c->add_option("--set", a.set,
                "KEY=VALUE: a value every rung shares, as `dataset --set` takes it (dataset.samples=2 for a quick run); a ladder's own key wins");
  c->add_option("--ladders", a.ladders, "run these ladders only (their names in SPEC)");
  c->add_flag("--resume", a.resume, "continue in DIR: keep verified samples and the scores of unchanged baselines");
  c->add_flag("--regenerate-changed", a.regenerate_changed, "with --resume: accept an edited spec, regenerate the samples it changes");
  c->add_option("--shard", a.shard,
                "K/M: generate every M-th sample of every rung from K only (K from 0; auto/M takes K from $SLURM_ARRAY_TASK_ID or "
                "$JOB_COMPLETION_INDEX); then run once without --shard to score");
  addCommonOptions(*c, a.common);
  return c;
}

int runBenchmarkCommand(const BenchmarkArgs& a, const std::string& command_line) {
  const auto threads = limitThreads(a.common.threads);
  std::vector<SpecOverride> set;
  for (const auto& kv : a.set) set.push_back(parseSpecOverride(kv, "--set", 0));
  BenchmarkSpec spec = readBenchmarkSpec(a.spec, set);
  selectLadders(spec, a.ladders);
  BenchmarkOptions opt;
  opt.resume = a.resume;
  opt.regenerate_changed = a.regenerate_changed;
  if (a.regenerate_changed && !a.resume) throw InputError("", 0, "--regenerate-changed goes with --resume");
  if (!a.shard.empty()) std::tie(opt.shard, opt.shards) = parseShard(a.shard);
  for (const auto& p : a.predictions) {
    const auto eq = p.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == p.size())
      throw InputError("", 0, "--predictions takes NAME=DIR (DIR/<ladder>/<rung>/<case>.nii.gz), not '" + p + "'");
    opt.predictions.push_back({p.substr(0, eq), p.substr(eq + 1)});
  }
  opt.memory_limit = memoryLimit(a.common);
  opt.command_line = command_line;
  if (!a.common.quiet) opt.progress = [](const std::string& m) { std::cerr << "benchmark: " << m << std::endl; };
  const BenchmarkSummary s = runBenchmark(spec, a.out, opt);
  if (!a.common.quiet) {
    std::cerr << "benchmark: " << s.samples_generated << " samples generated, " << s.samples_skipped << " kept, " << s.samples_failed << " failed; "
              << s.cases_segmented << " cases segmented; " << static_cast<int>(s.seconds + 0.5) << " s\n";
    if (s.scored)
      std::cerr << "benchmark: " << s.report.string() << ", " << s.csv.string() << "\n";
    else
      std::cerr << "benchmark: when every shard is done: angiosynth benchmark " << a.spec << " --out " << a.out << " --resume\n";
  }
  return s.samples_failed ? 1 : 0;
}

}  // namespace angiosynth::cli
