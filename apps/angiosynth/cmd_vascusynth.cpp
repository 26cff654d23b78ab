// `angiosynth vascusynth PARAM_LIST NAME_LIST VOXEL_WIDTH [NOISE_FILE...]`: VascuSynth's own
// arguments and directory layout, so existing batch scripts keep working.
#include <iostream>

#include "commands.hpp"
#include "core/error.hpp"
#include "files/output_guard.hpp"
#include "settings/param_checks.hpp"
#include "files/staged_directory.hpp"
#include "files/text_lines.hpp"
#include "pipeline/generate_sample.hpp"

namespace angiosynth::cli {

CLI::App* addVascuSynth(CLI::App& app, VascuSynthArgs& a) {
  auto* c = app.add_subcommand("vascusynth",
                               "run like VascuSynth: one tree per line of PARAM_LIST into the directory "
                               "named on the same line of NAME_LIST");
  c->add_option("PARAM_LIST", a.param_list, "file listing one parameter file per line")->required();
  c->add_option("NAME_LIST", a.name_list, "file listing one output directory per line")->required();
  c->add_option("VOXEL_WIDTH", a.output_voxel_width, "output image voxel width, in VOXEL_WIDTH's unit")->required()->check(finiteIn(1e-12, 1e12));
  c->add_option("NOISE_FILE", a.noise_files,
                "VascuSynth noise files (GAUSSIAN:, UNIFORM:, SALTPEPPER:, SHADOW: lines); the i-th (from 0) gives NAME/noise_image_<i>/");
  c->add_option("--slices", a.slices,
                "slice images: jpg (8-bit JPEG, what VascuSynth writes; lossy) or png (lossless); "
                "the exact image is image.nii.gz beside them")
      ->check(CLI::IsMember({"jpg", "png"}));
  addCommonOptions(*c, a.common, CommonInputs::WithVascuSynthFiles);
  return c;
}

int runVascuSynth(const VascuSynthArgs& a, const std::string& command_line) {
  const auto threads = limitThreads(a.common.threads);
  const auto params = readTextLines(a.param_list, "parameter list");
  const auto names = readTextLines(a.name_list, "name list");
  if (params.size() != names.size())
    throw InputError(a.name_list, names.empty() ? 0 : names.back().number,
                     std::to_string(names.size()) + " names for " + std::to_string(params.size()) + " parameter files in " + a.param_list +
                         "; give one name per parameter file");
  if (params.empty()) throw InputError(a.param_list, 0, "lists no parameter file");
  // Noise files are read (and every line checked) before anything is grown or written.
  std::vector<Profile> noise;
  for (std::size_t i = 0; i < a.noise_files.size(); ++i) {
    if (!std::filesystem::exists(a.noise_files[i])) throw InputError(a.noise_files[i], 0, "no such noise file");
    noise.push_back(readVascuSynthNoiseFile(a.noise_files[i]));
    noise.back().name = "noise_image_" + std::to_string(i);  // VascuSynth counts from 0
  }
  ReadOptions ro;
  ro.vascusynth_length_unit = a.common.vascusynth_unit;
  ro.vascusynth_rules = a.common.vascusynth_rules;
  // Read every parameter file before writing anything, so a typo in the last one costs nothing.
  // Maps too, and every output name checked, so nothing is written when any of them is wrong.
  std::vector<Scenario> scenarios;
  std::vector<std::filesystem::path> inputs{a.param_list, a.name_list};
  for (const auto& f : a.noise_files) inputs.push_back(f);
  for (const auto& l : params) {
    scenarios.push_back(readParameters(resolveInputPath(l.text, a.param_list, l.number), ro));
    for (const auto& f : scenarioInputs(scenarios.back())) inputs.push_back(f);
  }
  for (const auto& sc : scenarios) checkSampleInputs(sc, memoryLimit(a.common));
  const auto lineOf = [&](std::size_t i) { return a.name_list + ":" + std::to_string(names[i].number); };
  for (std::size_t i = 0; i < names.size(); ++i) checkOutputPath(names[i].text, inputs, lineOf(i));
  for (std::size_t i = 0; i < scenarios.size(); ++i) {
    const Scenario& sc = scenarios[i];
    // VascuSynth creates and overwrites its own files and leaves the others alone; so do we.
    StagedDirectory dir(names[i].text, ExistingOutput::Merge, inputs, lineOf(i));
    SampleRequest req;
    req.scenario = &sc;
    req.seed = sc.seed ? *sc.seed : freshSeed();
    req.graph_id = names[i].text + "/tree_structure.xml";
    req.command_line = command_line;
    req.memory_limit = memoryLimit(a.common);
    req.progress = progressPrinter(a.common, names[i].text);
    req.profiles = noise;
    req.vascusynth = VascuSynthLayout{a.output_voxel_width * sc.input_units.mm_per_length, a.slices};
    checkRange(req.vascusynth->voxel_mm, Limits::kMinVoxel, false, Limits::kMaxVoxel, false, Where{"VOXEL_WIDTH", 0}, "VOXEL_WIDTH (mm)");
    req.extra["output_voxel_width"] = {{"value", a.output_voxel_width * sc.input_units.mm_per_length}, {"unit", "mm"}};
    const SampleSummary made = generateSample(req, dir.path());
    dir.commit();
    if (!a.common.quiet) {
      std::cerr << "wrote " << names[i].text << "/tree_structure.xml (seed " << req.seed << ")";
      if (made.image_grid)
        std::cerr << "; image " << made.image_grid->dims[0] << " x " << made.image_grid->dims[1] << " x " << made.image_grid->dims[2]
                  << " voxels centred on the map voxels' corners (VascuSynth's grid)";
      std::cerr << "\n";
    }
  }
  return 0;
}

}  // namespace angiosynth::cli
