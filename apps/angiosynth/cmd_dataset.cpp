// `angiosynth dataset SPEC --out DIR` and its describe, finalize and verify subcommands.
#include <unistd.h>

#include <chrono>
#include <climits>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <tuple>

#include "commands.hpp"
#include "core/error.hpp"
#include "dataset/run_dataset.hpp"

namespace angiosynth::cli {
namespace {

DatasetSelection selection(const DatasetArgs& a, std::int64_t samples) {
  DatasetSelection s;
  s.end = samples;
  const int given = !a.index.empty() + !a.range.empty() + !a.shard.empty();
  if (given > 1) throw InputError("", 0, "give at most one of --index, --range, --shard");
  if (!a.index.empty()) {
    s.begin = a.index == "auto" ? indexFromEnvironment("--index") : parseIndex(a.index, "--index");
    if (s.begin >= samples)
      throw InputError("", 0,
                       "--index " + std::to_string(s.begin) + " is beyond the dataset's " + std::to_string(samples) + " samples; allowed: 0…" +
                           std::to_string(samples - 1));
    s.end = s.begin + 1;
    s.part = "index-" + std::to_string(s.begin);
  } else if (!a.range.empty()) {
    const auto colon = a.range.find(':');
    if (colon == std::string::npos) throw InputError("", 0, "--range takes A:B (samples A to B-1)");
    s.begin = parseIndex(a.range.substr(0, colon), "--range");
    s.end = std::min(samples, parseIndex(a.range.substr(colon + 1), "--range"));
    if (s.begin >= s.end) throw InputError("", 0, "--range " + a.range + " holds no sample of 0…" + std::to_string(samples - 1));
    s.part = "range-" + std::to_string(s.begin) + "-" + std::to_string(s.end);
  } else if (!a.shard.empty()) {
    std::tie(s.shard, s.shards) = parseShard(a.shard);
    s.part = "shard-" + std::to_string(s.shard) + "-of-" + std::to_string(s.shards);
  }
  if (s.begin >= samples)
    throw InputError("", 0, "index " + std::to_string(s.begin) + " is beyond the dataset's " + std::to_string(samples) + " samples");
  return s;
}

std::string duration(double s) {
  char buf[32];
  if (s < 60)
    std::snprintf(buf, sizeof buf, "%.0fs", s);
  else if (s < 3600)
    std::snprintf(buf, sizeof buf, "%dm%02ds", int(s) / 60, int(s) % 60);
  else
    std::snprintf(buf, sizeof buf, "%dh%02dm", int(s) / 3600, int(s) / 60 % 60);
  return buf;
}

std::vector<SpecOverride> overrides(const DatasetArgs& a) {
  std::vector<SpecOverride> out;
  for (const auto& s : a.set) out.push_back(parseSpecOverride(s, "--set", 0));
  return out;
}

int report(const DatasetCheck& c, const char* verb) {
  for (const auto& w : c.warnings) std::cerr << "warning: " << w << "\n";
  for (const auto& p : c.problems) std::cerr << p << "\n";
  std::cerr << verb << ": " << c.ok << " of " << c.samples << " samples ok, " << c.problems.size() << " problem"
            << (c.problems.size() == 1 ? "" : "s") << "\n";
  return c.problems.empty() ? 0 : 1;
}

}  // namespace

CLI::App* addDataset(CLI::App& app, DatasetArgs& a) {
  auto* c = app.add_subcommand("dataset", "generate an nnU-Net v2 dataset from a spec; or describe, finalize, verify");
  c->add_option("SPEC", a.spec, "dataset spec (.toml)");
  c->add_option("--out", a.out, "parent directory of DatasetNNN_Name (e.g. $nnUNet_raw)");
  c->add_option("--index", a.index, "generate sample I only; auto: $SLURM_ARRAY_TASK_ID or $JOB_COMPLETION_INDEX");
  c->add_option("--range", a.range, "generate samples A to B-1");
  c->add_option("--shard", a.shard, "generate every M-th sample from K (K from 0); auto/M takes K from the environment");
  const char* set_help =
      "replace a value of the spec without editing it: KEY=VALUE, KEY dotted as in the spec (tree.terminals=200, "
      "dataset.profile='\"tof_mra\"') or profile.<effect>.<parameter> for the image profile's effects (profile.gaussian.sigma=40); "
      "recorded in spec.json";
  c->add_option("--set", a.set, set_help);
  c->add_flag("--resume", a.resume, "skip samples whose files verify against the manifest");
  c->add_flag("--regenerate-changed", a.regenerate_changed,
              "with --resume: accept an edited spec and regenerate exactly the samples whose resolved parameters changed");
  c->add_option("--samples-in-flight", a.in_flight, "samples generated at once (default: one per thread, fewer if memory is short)")
      ->check(CLI::PositiveNumber);
  addCommonOptions(*c, a.common);
  auto* d = c->add_subcommand("describe", "print sample I's resolved parameter file without generating it");
  d->add_option("SPEC", a.spec, "dataset spec (.toml)")->required();
  d->add_option("--index", a.index, "sample index")->required();
  d->add_option("--set", a.set, set_help);
  auto* f = c->add_subcommand("finalize", "merge the shards' manifests; write manifest.jsonl, dataset.json, provenance.json");
  f->add_option("DIR", a.dir, "the DatasetNNN_Name directory")->required();
  auto* v = c->add_subcommand("verify", "re-hash every file; report missing, failed and corrupt samples (exit 1 if any)");
  v->add_option("DIR", a.dir, "the DatasetNNN_Name directory")->required();
  c->require_subcommand(0, 1);
  a.describe = d;
  a.finalize = f;
  a.verify = v;
  return c;
}

int runDatasetCommand(const DatasetArgs& a, const std::string& command_line) {
  if (a.describe->parsed()) {
    const DatasetSpec spec = readDatasetSpec(a.spec, overrides(a));
    const auto i = parseIndex(a.index, "--index");
    if (i >= spec.samples) throw InputError(a.spec, 0, "--index " + a.index + " is beyond the " + std::to_string(spec.samples) + " samples");
    const ResolvedSample r = resolveSample(spec, i);
    std::cout << "# sample " << r.index << " (" << r.id << "), seed " << r.seed << ", image profile " << r.profile << "\n";
    for (const auto& o : spec.overrides)
      if (o.key.rfind("profile.", 0) == 0) std::cout << "# image profile with " << o.key.substr(8) << " = " << o.value << "\n";
    std::cout << readableParameters(r);
    return 0;
  }
  if (a.finalize->parsed()) return report(finalizeDataset(a.dir), "finalize");
  if (a.verify->parsed()) return report(verifyDataset(a.dir), "verify");
  if (a.spec.empty() || a.out.empty()) throw InputError("", 0, "dataset: give SPEC and --out DIR (or describe, finalize, verify)");
  const auto threads = limitThreads(a.common.threads);
  const DatasetSpec spec = readDatasetSpec(a.spec, overrides(a));
  const DatasetSelection sel = selection(a, spec.samples);
  DatasetRunOptions opt;
  opt.resume = a.resume;
  opt.regenerate_changed = a.regenerate_changed;
  if (a.regenerate_changed && !a.resume) throw InputError("", 0, "--regenerate-changed goes with --resume");
  opt.samples_in_flight = a.in_flight;
  opt.memory_limit = memoryLimit(a.common);
  opt.command_line = command_line;
  const bool terminal = isatty(STDERR_FILENO) && !a.common.quiet;
  const auto start = std::chrono::steady_clock::now();
  std::int64_t failures = 0;
  opt.on_sample = [&](const nlohmann::json& e, std::int64_t done, std::int64_t total) {
    failures += e["status"] != "ok";
    if (a.common.quiet) return;
    if (!terminal) {  // one JSON line per sample for logs
      nlohmann::json line{{"id", e["id"]},           {"index", e["index"]}, {"status", e["status"]},
                          {"seconds", e["seconds"]}, {"done", done},        {"total", total}};
      if (e.contains("error")) line["error"] = e["error"];
      std::cout << line.dump() << std::endl;
      return;
    }
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const double rate = done / std::max(s, 1e-9);
    const int width = 30, filled = static_cast<int>(width * done / std::max<std::int64_t>(total, 1));
    std::fprintf(stderr, "\r[%s%s] %lld/%lld  %.2f samples/s  ETA %s%s   ", std::string(filled, '#').c_str(),
                 std::string(width - filled, '.').c_str(), static_cast<long long>(done), static_cast<long long>(total), rate,
                 duration((total - done) / std::max(rate, 1e-9)).c_str(), failures ? (" (" + std::to_string(failures) + " failed)").c_str() : "");
    if (done == total) std::fprintf(stderr, "\n");
    std::fflush(stderr);
  };
  const DatasetRunReport r = runDataset(spec, a.out, sel, opt);
  if (!a.common.quiet)
    std::cerr << r.dir.string() << ": " << r.generated << " generated, " << r.skipped << " skipped (verified), " << r.failed << " failed ("
              << r.in_flight << " at a time), " << duration(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()) << "\n";
  int code = r.failed ? 1 : 0;
  if (sel.part == "all") {
    const DatasetCheck c = finalizeDataset(r.dir);
    if (!c.problems.empty()) code = report(c, "finalize");
  } else if (!a.common.quiet) {
    std::cerr << "when every part is done: angiosynth dataset finalize " << r.dir.string() << "\n";
  }
  return code;
}

}  // namespace angiosynth::cli
