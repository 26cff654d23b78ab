// `angiosynth generate PARAMS`: one sample from a TOML or VascuSynth parameter file.
#include <iostream>

#include "commands.hpp"
#include "core/format.hpp"
#include "core/error.hpp"
#include "files/staged_directory.hpp"
#include "config/sample_settings.hpp"
#include "pipeline/generate_sample.hpp"

namespace angiosynth::cli {

CLI::App* addGenerate(CLI::App& app, GenerateArgs& a) {
  auto* c = app.add_subcommand("generate", "grow one vascular tree from a parameter file (.toml, or VascuSynth's format)");
  c->add_option("PARAMS", a.params, "parameter file: .toml (native, with units) or a VascuSynth parameter file")->required();
  c->add_option("--out", a.out, "output directory (default: out/<PARAMS name>)");
  c->add_option("--seed", a.seed, "random seed (default: the file's seed, else fresh and recorded in sample.json)")
      ->check(CLI::Range(std::uint64_t(0), std::uint64_t(INT64_MAX)));  // as TOML seeds: int64 >= 0
  a.image.add(*c, imageSettings());
  a.output.add(*c, outputSettings());
  c->add_option("--profile", a.profiles,
                "degradation profiles, overriding [degrade] profiles: shipped names (clean, vascusynth, cta, tof_mra, "
                "two_photon, octa, domain_randomisation), .toml profiles, or VascuSynth noise files; one image_<name> each")
      ->delimiter(',');
  c->add_flag("--no-profiles", a.no_profiles, "write the clean image only, ignoring [degrade] profiles");
  c->add_option("--part", a.part,
                "grow only part I of a tree grown in parts ([tree] parts = K) into --parts-dir, as one task of a cluster array (0-based; a "
                "Slurm array passes $SLURM_ARRAY_TASK_ID); a rerun keeps a finished part")
      ->check(CLI::Range(0, 4095));
  c->add_flag("--join", a.join, "join the parts that --part tasks grew in --parts-dir into the sample, instead of growing the tree");
  c->add_option("--parts-dir", a.parts_dir, "where --part writes its part and --join reads them (default: --out's path with .parts appended)");
  c->add_flag("--force", a.force, "replace an earlier angiosynth output in --out (only the files it wrote there)");
  addCommonOptions(*c, a.common, CommonInputs::WithVascuSynthFiles);
  return c;
}

int runGenerate(const GenerateArgs& a, const std::string& command_line) {
  const auto threads = limitThreads(a.common.threads);
  ReadOptions ro;
  ro.vascusynth_length_unit = a.common.vascusynth_unit;
  ro.vascusynth_rules = a.common.vascusynth_rules;
  if (a.common.vascusynth_rules && std::filesystem::path(a.params).extension() == ".toml")
    throw InputError(a.params, 0, "--vascusynth-rules is for VascuSynth parameter files; in a .toml file write [tree] rules = \"vascusynth\"");
  Scenario sc = readParameters(a.params, ro);
  a.image.applyTo(sc.image);
  a.output.applyTo(sc);
  const std::filesystem::path out =
      a.out.empty() ? std::filesystem::path("out") / std::filesystem::path(a.params).stem() : std::filesystem::path(a.out);
  if (a.part >= 0 && a.join) throw InputError("--part", 0, "with --join; allowed: --part I (one task) or --join (after every task)");
  if (!a.parts_dir.empty() && a.part < 0 && !a.join) throw InputError("--parts-dir", 0, "without --part or --join; allowed: with either");
  if ((a.part >= 0 || a.join) && !a.seed && !sc.seed)
    throw InputError(a.params, 0,
                     std::string(a.join ? "--join" : "--part") +
                         " needs a fixed seed, so that every task grows the same trunk; allowed: [sample] seed in the file, or --seed");
  const std::filesystem::path parts_dir = a.parts_dir.empty() ? std::filesystem::path(out.string() + ".parts") : std::filesystem::path(a.parts_dir);
  std::vector<std::filesystem::path> inputs = scenarioInputs(sc);
  for (const auto& p : a.profiles) inputs.push_back(p);
  SampleRequest req;
  req.scenario = &sc;
  req.seed = a.seed ? *a.seed : (sc.seed ? *sc.seed : freshSeed());
  req.gxl_dialect = sc.gxl_dialect;
  req.graph_id = "tree";
  req.command_line = command_line;
  req.memory_limit = memoryLimit(a.common);
  req.progress = progressPrinter(a.common, "growing");
  if (a.no_profiles) req.profiles.emplace();
  if (!a.profiles.empty()) {
    req.profiles.emplace();
    for (const auto& p : a.profiles) req.profiles->push_back(loadProfile(p, "--profile", 0));
  }
  if (a.part >= 0) {
    req.progress = {};
    const PartTaskSummary done = growSamplePart(req, a.part, parts_dir);
    if (!a.common.quiet)
      std::cerr << (done.resumed ? "kept " : "wrote ") << done.file.string() << ": part " << a.part << ", " << done.terminals << " terminals, "
                << show(done.seconds) << " s growth" << (done.resumed ? " (grown earlier from the same parameters and seed)" : "") << "\n";
    return 0;
  }
  if (a.join) req.parts_dir = parts_dir;
  StagedDirectory dir(out, a.force ? ExistingOutput::ReplaceOwn : ExistingOutput::Refuse, inputs);
  const SampleSummary made = generateSample(req, dir.path());
  dir.commit();
  if (!a.common.quiet)
    std::cerr << "wrote " << dir.target().string() << ": " << made.terminals << " terminals, total volume " << made.total_volume_mm3 << " mm^3, "
              << made.intersecting_pairs << " intersecting pairs, seed " << req.seed << ", " << show(made.grow_seconds) << " s growth"
              << (made.image_grid ? "; image " + std::to_string(made.image_grid->dims[0]) + " x " + std::to_string(made.image_grid->dims[1]) + " x " +
                                        std::to_string(made.image_grid->dims[2]) + " voxels of " + show(made.image_grid->spacing_mm.x) +
                                        " mm, centres (i + 1/2) voxels from the frame's corner"
                                  : std::string())
              << "\n";
  printWarnings(made.warnings, (dir.target() / "sample.json").string() + " (statistics.surface.warnings)");
  return 0;
}

}  // namespace angiosynth::cli
