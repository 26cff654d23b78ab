// `angiosynth score PRED SAMPLE_DIR`: a segmentation scored against a generated sample's exact
// truth (src/score). Thin: options, the files, the report.
#include <filesystem>
#include <fstream>
#include <iostream>

#include "commands.hpp"
#include "core/error.hpp"
#include "files/atomic_file.hpp"
#include "files/output_guard.hpp"
#include "score/case_scores.hpp"
#include "score/calibre_plot.hpp"
#include "score/dataset_scores.hpp"
#include "io/volume_writers.hpp"

namespace angiosynth::cli {

namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

// Output files: each its own, never an input, new unless --force; written whole or not at all.
void checkOutputs(const ScoreArgs& a) {
  checkOutputFiles({{a.out, "--out"}, {a.csv, "--csv"}, {a.plot, "--plot"}}, {a.prediction, a.sample, a.dataset, a.predictions}, a.force);
}

void writePngAtomically(const fs::path& file, const Image8& image) {
  AtomicFile f(file);
  writePng(f.stream(), file, image);
  f.commit();
}

}  // namespace

CLI::App* addScore(CLI::App& app, ScoreArgs& a) {
  auto* c = app.add_subcommand("score",
                               "score a segmentation (NIfTI, voxels > 0 = vessel) against a generated sample's exact truth: "
                               "overlap, surface distances, recall by calibre, vessels detected");
  c->add_option("PRED", a.prediction, "the prediction (.nii or .nii.gz on the sample's grid)");
  c->add_option("SAMPLE_DIR", a.sample, "the sample directory angiosynth generate wrote");
  c->add_option("--dataset", a.dataset, "a dataset angiosynth made (DatasetNNN_Name): score every case, with --predictions");
  c->add_option("--predictions", a.predictions, "with --dataset: the directory of predictions, <case>.nii.gz (nnU-Net naming)");
  c->add_option("--out", a.out, "write the scores as JSON here (default: print them)");
  c->add_option("--csv", a.csv, "also write the headline numbers as one CSV row here");
  c->add_option("--tolerance", a.options.tolerance_mm, "NSD tolerance in mm (default: the smallest voxel edge)")->check(finiteIn(0, 1e6));
  c->add_option("--boundary-width", a.options.boundary_width_mm,
                "Boundary IoU's band width in mm (default: 2 % of the image diagonal, at least one voxel)")
      ->check(finiteIn(0, 1e6));
  c->add_flag("--topcow", a.topcow, "TopCoW's conventions: 26-neighbour borders, 90 mm when a mask is empty, Dice 0 when both are");
  c->add_option("--bins-voxels", a.bins_voxels, "calibre bins: increasing lower edges of the radius in voxels (default 0 0.5 1 2 4)")
      ->expected(1, 64);
  c->add_option("--bins-mm", a.bins_mm, "calibre bins in mm: increasing lower edges of the radius")->expected(1, 64);
  c->add_option("--plot", a.plot, "also draw the calibre curve (recall by radius in voxels) as a PNG here");
  c->add_flag("--force", a.force, "replace existing --out, --csv and --plot files");
  addCommonOptions(*c, a.common);
  return c;
}

int runScore(const ScoreArgs& a) {
  const auto guard = limitThreads(a.common.threads);
  checkOutputs(a);
  ScoreOptions opt = a.options;
  if (a.topcow) opt.conventions = ScoreConventions::TopCoW;
  opt.memory_limit = memoryLimit(a.common);
  if (!a.bins_voxels.empty()) opt.bins_voxels = a.bins_voxels;
  opt.bins_mm = a.bins_mm;
  if (const auto why = opt.invalid(); !why.empty()) throw InputError("", 0, why);
  const bool dataset = !a.dataset.empty() || !a.predictions.empty();
  if (dataset ? (a.dataset.empty() || a.predictions.empty() || !a.prediction.empty()) : (a.prediction.empty() || a.sample.empty()))
    throw InputError("", 0, "give PRED SAMPLE_DIR (one case) or --dataset DIR --predictions DIR (every case of a dataset)");
  Json j;
  std::string csv;
  if (dataset) {
    j = scoreDataset(a.dataset, a.predictions, opt, progressPrinter(a.common, "scoring"), csv);
  } else {
    const CaseScores scores = scoreCase(a.prediction, sampleTruth(a.sample), opt);
    j = scores.toJson();
    csv = scoreCsvHeader() + scoreCsvRow(a.prediction, scores);
  }
  if (a.out.empty())
    std::cout << j.dump(2) << "\n";
  else
    writeFileAtomically(a.out, j.dump(2) + "\n");
  if (!a.csv.empty()) writeFileAtomically(a.csv, csv);
  if (!a.plot.empty()) {
    CalibreCurve curve = calibreCurve(j, "");
    curve.name = std::filesystem::path(dataset ? a.predictions : a.prediction).filename().string();
    writePngAtomically(a.plot, plotCalibreCurves({curve}));
  }
  if (!a.common.quiet) {
    const Json& s = dataset ? j["summary"] : j;
    const auto show = [&](const char* pointer) {
      const Json::json_pointer p(pointer);
      return s.contains(p) && s.at(p).is_number() ? std::to_string(s.at(p).get<double>()) : std::string("-");
    };
    if (dataset)
      std::cerr << j["cases"] << " cases: mean Dice " << show("/dice/mean") << ", mean HD95 " << show("/hd95_mm/mean")
                << " mm, mean centreline recall " << show("/centreline_recall/mean") << "\n";
    else
      std::cerr << "Dice " << show("/overlap/dice") << ", HD95 " << show("/surface/hd95_mm") << " mm, centreline recall "
                << show("/centreline/recall") << "\n";
  }
  return 0;
}

CLI::App* addPlotCalibre(CLI::App& app, PlotCalibreArgs& a) {
  auto* c = app.add_subcommand("plot-calibre",
                               "draw the calibre curves of score results (JSON of `angiosynth score`, one case or a "
                               "dataset's mean) as one PNG: curve k in colour k, named in the legend");
  c->add_option("OUT", a.out, "the PNG to write")->required();
  c->add_option("SCORES", a.scores, "score results (.json)")->required()->expected(1, 8);
  c->add_option("--labels", a.labels, "the legend's name of each curve, in order (default: each file's name without .json)")->delimiter(',');
  c->add_flag("--force", a.force, "replace an existing OUT");
  return c;
}

int runPlotCalibre(const PlotCalibreArgs& a) {
  checkOutputFiles({{a.out, "OUT"}}, {a.scores.begin(), a.scores.end()}, a.force);
  if (!a.labels.empty() && a.labels.size() != a.scores.size())
    throw InputError(
        "", 0,
        "--labels gives " + std::to_string(a.labels.size()) + " names for " + std::to_string(a.scores.size()) + " score results; give one per file");
  std::vector<CalibreCurve> curves;
  for (const auto& f : a.scores) {
    std::ifstream in(f);
    if (!in) throw InputError(f, 0, "cannot read this file");
    const Json j = Json::parse(in, nullptr, /*allow_exceptions=*/false);
    if (j.is_discarded() || !j.is_object()) throw InputError(f, 0, "is not a score result (JSON of angiosynth score)");
    const CalibreCurve c = calibreCurve(j, f);
    if (c.lower.empty()) throw InputError(f, 0, "holds no calibre bins; allowed: the JSON angiosynth score writes");
    if (!curves.empty() && c.lower != curves.front().lower) throw InputError(f, 0, "has other calibre bins than " + a.scores.front());
    curves.push_back(c);
    curves.back().name = a.labels.empty() ? std::filesystem::path(f).stem().string() : a.labels[curves.size() - 1];
  }
  writePngAtomically(a.out, plotCalibreCurves(curves));
  return 0;
}

}  // namespace angiosynth::cli
