// `angiosynth score`: a segmentation scored against a truth (src/score). Thin: options, the
// files, the report.
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>

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
  checkOutputFiles({{a.out, "--out"}, {a.csv, "--csv"}, {a.class_csv, "--class-csv"}, {a.plot, "--plot"}},
                   {a.prediction, a.truth, a.dataset, a.predictions, a.centreline, a.radius, a.graph}, a.force);
}

void writePngAtomically(const fs::path& file, const Image8& image) {
  AtomicFile f(file);
  writePng(f.stream(), file, image);
  f.commit();
}

// --legend 1=artery,2=vein
std::map<int, std::string> parseLegend(const std::string& text) {
  std::map<int, std::string> legend;
  std::stringstream in(text);
  std::string item;
  const auto bad = [&](const std::string& what) {
    return InputError("--legend", 0, "\"" + what + "\" is not VALUE=NAME; allowed: a comma-separated list such as 1=artery,2=vein (values 1 to 255)");
  };
  while (std::getline(in, item, ',')) {
    const auto eq = item.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == item.size()) throw bad(item);
    try {
      std::size_t used = 0;
      const int v = std::stoi(item.substr(0, eq), &used);
      if (used != eq || v < 1 || v > 255) throw bad(item);
      legend[v] = item.substr(eq + 1);
    } catch (const std::logic_error&) { throw bad(item); }
  }
  return legend;
}

// The truth of `score PRED TRUTH`: a sample directory, or an annotation with what is given beside it.
TruthFiles plainTruth(const ScoreArgs& a) {
  const bool extras = !a.centreline.empty() || !a.radius.empty() || !a.graph.empty() || !a.legend.empty();
  if (fs::is_directory(a.truth)) {
    if (extras) throw InputError("", 0, "--centreline, --radius, --graph and --legend go with an annotation file; a sample directory has its own");
    return sampleTruth(a.truth);
  }
  TruthFiles t = annotationTruth(a.truth);
  t.centerline = a.centreline, t.radius = a.radius;
  if (!a.graph.empty()) {
    const fs::path edges = a.graph;
    if (edges.filename() != "edges.csv" || !fs::is_regular_file(edges) || !fs::is_regular_file(edges.parent_path() / "nodes.csv"))
      throw InputError(a.graph, 0, "is not a graph's edges.csv with nodes.csv beside it; allowed: the edges.csv angiosynth generate writes");
    t.edges = edges;
    if (fs::is_regular_file(edges.parent_path() / "keypoints.csv")) t.keypoints = edges.parent_path() / "keypoints.csv";
  }
  if (!a.legend.empty()) t.legend = parseLegend(a.legend);
  return t;
}

DatasetTruth datasetTruth(const std::string& name) {
  if (name == "training") return DatasetTruth::Training;
  if (name == "exact") return DatasetTruth::Exact;
  throw InputError("--truth", 0, "\"" + name + "\" is not a truth; allowed: training (labelsTr, under the label policy) or exact (the exact mask)");
}

}  // namespace

CLI::App* addScore(CLI::App& app, ScoreArgs& a) {
  auto* c = app.add_subcommand("score",
                               "score a segmentation (NIfTI, voxels > 0 = vessel, values above 1 = classes) against a truth: a generated "
                               "sample's exact truth, a dataset's cases, or any annotation; overlap, surface distances, topology, recall "
                               "by calibre, vessels detected, per class and by a challenge's label scheme");
  c->add_option("PRED", a.prediction, "the prediction (.nii or .nii.gz on the truth's grid)");
  c->add_option("TRUTH", a.truth, "a sample directory angiosynth generate wrote, or an annotation (.nii, .nii.gz; binary or labelled)");
  c->add_option("--centreline", a.centreline, "with an annotation: its exact centreline (NIfTI, > 0 on the centreline), for centreline recall");
  c->add_option("--radius", a.radius, "with --centreline: the vessel radius there (NIfTI, mm), for recall by calibre");
  c->add_option("--graph", a.graph, "with an annotation: the edges.csv of its vessel graph (nodes.csv beside), for vessels and key points");
  c->add_option("--legend", a.legend, "names of the annotation's class values: 1=artery,2=vein (every other value present is scored as \"label N\")");
  c->add_option("--label-scheme", a.label_scheme,
                "class names and challenge metrics of a label scheme: topcow2024, topbrain2025-ct, or a JSON file of one (docs/scoring.md)");
  c->add_option("--dataset", a.dataset,
                "a dataset angiosynth made (DatasetNNN_Name): with --predictions, score its cases that have a prediction; with PRED "
                "and --case, one case");
  c->add_option("--predictions", a.predictions, "with --dataset: the directory of predictions, <case>.nii.gz (nnU-Net naming)");
  c->add_option("--case", a.case_id, "with --dataset and PRED: the case PRED is a prediction of");
  c->add_option("--cases", a.cases, "with --predictions: score only these cases")->delimiter(',');
  c->add_option("--splits", a.splits, "with --predictions and --fold: nnU-Net's splits_final.json; the fold's validation cases are scored");
  c->add_option("--fold", a.fold, "with --splits: the fold (0, 1, …)")->check(CLI::Range(0, 1000));
  c->add_option("--truth", a.truth_kind,
                "with --dataset: training (default; labelsTr, the label the network learned, under the dataset's label policy, its "
                "ignore label counting neither way) or exact (the exact mask)");
  c->add_option("--out", a.out, "write the scores as JSON here (default: print them)");
  c->add_option("--csv", a.csv, "also write the headline numbers as CSV here (one row per case)");
  c->add_option("--class-csv", a.class_csv, "with --predictions: also write each class's numbers over the cases as CSV here");
  c->add_option("--tolerance", a.options.tolerance_mm, "NSD tolerance in mm (default: the smallest voxel edge)")->check(finiteIn(0, 1e6));
  c->add_option("--boundary-width", a.options.boundary_width_mm,
                "Boundary IoU's band width in mm (default: 2 % of the image diagonal, at least one voxel)")
      ->check(finiteIn(0, 1e6));
  c->add_option("--grid-tolerance", a.options.grid_tolerance_voxels,
                "how far (voxels) the two files' voxel-to-world affines may place a corner voxel apart (default 0.01)")
      ->check(finiteIn(0, 1e3));
  c->add_flag("--topcow", a.topcow,
              "TopCoW's conventions: 26-neighbour borders, 90 mm (the label scheme's bound) for a distance to an empty mask, 0 for every "
              "ratio of empty masks");
  c->add_option("--bins-voxels", a.bins_voxels, "calibre bins: increasing lower edges of the radius in voxels (default 0 0.5 1 2 4)")
      ->expected(1, 64);
  c->add_option("--bins-mm", a.bins_mm, "calibre bins in mm: increasing lower edges of the radius")->expected(1, 64);
  c->add_option("--plot", a.plot, "also draw the calibre curve (recall by radius in voxels) as a PNG here");
  c->add_flag("--force", a.force, "replace existing --out, --csv, --class-csv and --plot files");
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
  if (!a.label_scheme.empty()) opt.scheme = labelScheme(a.label_scheme);
  if (const auto why = opt.invalid(); !why.empty()) throw InputError("", 0, why);
  const bool many = !a.predictions.empty();
  const bool one_of_dataset = !a.dataset.empty() && !many;
  const auto usage = [] {
    return InputError("", 0,
                      "give PRED TRUTH (one case against a sample directory or an annotation), PRED --dataset DIR --case ID (one case of "
                      "a dataset) or --dataset DIR --predictions DIR (the dataset's cases that have a prediction)");
  };
  if (many             ? (a.dataset.empty() || !a.prediction.empty() || !a.truth.empty() || !a.case_id.empty())
      : one_of_dataset ? (a.prediction.empty() || a.case_id.empty() || !a.truth.empty())
                       : (a.prediction.empty() || a.truth.empty()))
    throw usage();
  if (!many && (!a.cases.empty() || !a.splits.empty() || a.fold >= 0 || !a.class_csv.empty()))
    throw InputError("", 0, "--cases, --splits, --fold and --class-csv select and summarise the cases of --dataset DIR --predictions DIR");
  if (!a.splits.empty() != (a.fold >= 0)) throw InputError("", 0, "--splits and --fold go together: the fold's validation cases of nnU-Net's splits");
  if (!a.splits.empty() && !a.cases.empty()) throw InputError("", 0, "give --cases or --splits with --fold, not both");
  if (a.dataset.empty() && a.truth_kind != "training")
    throw InputError("", 0, "--truth chooses between a dataset case's training label and its exact mask; give --dataset");
  Json j;
  std::string csv, class_csv;
  if (many) {
    DatasetScoreOptions select;
    select.truth = datasetTruth(a.truth_kind);
    select.cases = a.cases;
    select.splits = a.splits;
    select.fold = a.fold;
    DatasetScores s = scoreDataset(a.dataset, a.predictions, opt, select, progressPrinter(a.common, "scoring"));
    j = std::move(s.results);
    csv = std::move(s.csv);
    class_csv = std::move(s.class_csv);
    if (!s.missing.empty() && !a.common.quiet) {
      std::cerr << "warning: no prediction for " << s.missing.size() << " of the " << s.missing.size() + s.scored.size() << " cases selected:";
      for (const auto& id : s.missing) std::cerr << ' ' << id;
      std::cerr << " (listed in missing_predictions)\n";
    }
  } else {
    const TruthFiles truth = one_of_dataset ? datasetCaseTruth(a.dataset, a.case_id, datasetTruth(a.truth_kind)) : plainTruth(a);
    const CaseScores scores = scoreCase(a.prediction, truth, opt);
    j = scores.toJson();
    csv = scoreCsvHeader() + scoreCsvRow(a.prediction, scores);
    if (!a.common.quiet && j.contains("per_class") && j["per_class"].contains("warnings"))
      for (const auto& w : j["per_class"]["warnings"]) std::cerr << "warning: " << w.get<std::string>() << "\n";
  }
  if (!a.class_csv.empty() && class_csv.empty()) throw InputError("--class-csv", 0, "the truth has no classes to summarise");
  if (a.out.empty())
    std::cout << j.dump(2) << "\n";
  else
    writeFileAtomically(a.out, j.dump(2) + "\n");
  if (!a.csv.empty()) writeFileAtomically(a.csv, csv);
  if (!a.class_csv.empty()) writeFileAtomically(a.class_csv, class_csv);
  if (!a.plot.empty()) {
    CalibreCurve curve = calibreCurve(j, "");
    if (curve.lower.empty()) throw InputError("--plot", 0, "the truth has no centreline and radius to draw a calibre curve from");
    curve.name = std::filesystem::path(many ? a.predictions : a.prediction).filename().string();
    writePngAtomically(a.plot, plotCalibreCurves({curve}));
  }
  if (!a.common.quiet) {
    const Json& s = many ? j["summary"] : j;
    const auto show = [&](const char* pointer) {
      const Json::json_pointer p(pointer);
      return s.contains(p) && s.at(p).is_number() ? std::to_string(s.at(p).get<double>()) : std::string("-");
    };
    if (many)
      std::cerr << j["cases"] << (j["cases"] == 1 ? " case" : " cases") << " against " << j["truth_is"].get<std::string>() << ": mean Dice "
                << show("/dice/mean") << ", mean HD95 " << show("/hd95_mm/mean") << " mm, mean centreline recall " << show("/centreline_recall/mean")
                << "\n";
    else
      std::cerr << "against " << j["truth_is"].get<std::string>() << ": Dice " << show("/overlap/dice") << ", HD95 " << show("/surface/hd95_mm")
                << " mm, centreline recall " << show("/centreline/recall") << "\n";
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
