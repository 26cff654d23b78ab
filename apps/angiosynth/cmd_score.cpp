// `angiosynth score PRED SAMPLE_DIR`: a segmentation scored against a generated sample's exact
// truth (src/score). Thin: options, the files, the report.
#include <filesystem>
#include <iostream>

#include "commands.hpp"
#include "core/error.hpp"
#include "io/text_file.hpp"
#include "score/case_scores.hpp"

namespace angiosynth::cli {

namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

std::string number(const Json& v) {
  if (v.is_null()) return "";
  std::ostringstream o;
  o.precision(17);
  o << v.get<double>();
  return o.str();
}

// One CSV row of the headline numbers (the JSON holds everything).
void writeCsv(std::ostream& o, const Json& j) {
  o << "prediction,dice,jaccard,precision,recall,hd_mm,hd95_mm,assd_mm,masd_mm,nsd,centreline_recall,vessels_detected_rate,"
       "tree_length_detected\n";
  const Json& ov = j["overlap"];
  const Json& s = j["surface"];
  const Json none;
  const Json& v = j.contains("vessels") ? j["vessels"] : none;
  o << '"' << j["prediction"].get<std::string>() << '"';
  for (const Json* x : {&ov["dice"], &ov["jaccard"], &ov["precision"], &ov["recall"], &s["hd_mm"], &s["hd95_mm"], &s["assd_mm"],
                        &s["masd_mm"], &s["nsd"], &j["centreline"]["recall"]})
    o << ',' << number(*x);
  o << ',' << (v.is_null() ? "" : number(v["detected_rate"])) << ',' << (v.is_null() ? "" : number(v["tree_length_detected"])) << '\n';
}

// Output files are new files, or --force; never an input.
void checkOutput(const std::string& out, const ScoreArgs& a) {
  if (out.empty()) return;
  const fs::path o = fs::weakly_canonical(out);
  if (o == fs::weakly_canonical(a.prediction) || o.parent_path() == fs::weakly_canonical(a.sample) ||
      o == fs::weakly_canonical(a.sample))
    throw InputError(out, 0, "is the prediction or lies in the truth sample; allowed: a file elsewhere");
  if (fs::exists(o) && !a.force) throw InputError(out, 0, "exists; give --force to replace it");
}

}  // namespace

CLI::App* addScore(CLI::App& app, ScoreArgs& a) {
  auto* c = app.add_subcommand("score", "score a segmentation (NIfTI, voxels > 0 = vessel) against a generated sample's exact truth: "
                                        "overlap, surface distances, recall by calibre, vessels detected");
  c->add_option("PRED", a.prediction, "the prediction (.nii or .nii.gz on the sample's grid)")->required();
  c->add_option("SAMPLE_DIR", a.sample, "the sample directory angiosynth generate wrote")->required();
  c->add_option("--out", a.out, "write the scores as JSON here (default: print them)");
  c->add_option("--csv", a.csv, "also write the headline numbers as one CSV row here");
  c->add_option("--tolerance", a.tolerance_mm, "NSD tolerance in mm (default: the smallest voxel edge)")->check(finiteIn(0, 1e6));
  c->add_flag("--topcow", a.topcow, "TopCoW's conventions: 26-neighbour borders, 90 mm when a mask is empty, Dice 0 when both are");
  c->add_option("--bins-voxels", a.bins_voxels, "calibre bins: increasing lower edges of the radius in voxels (default 0 0.5 1 2 4)")
      ->expected(1, 64);
  c->add_option("--bins-mm", a.bins_mm, "calibre bins in mm: increasing lower edges of the radius")->expected(1, 64);
  c->add_flag("--force", a.force, "replace existing --out and --csv files");
  addCommonOptions(*c, a.common);
  return c;
}

int runScore(const ScoreArgs& a) {
  const auto guard = limitThreads(a.common.threads);
  checkOutput(a.out, a);
  checkOutput(a.csv, a);
  ScoreOptions opt;
  opt.tolerance_mm = a.tolerance_mm;
  opt.topcow = a.topcow;
  opt.memory_limit = memoryLimit(a.common);
  for (const auto* bins : {&a.bins_voxels, &a.bins_mm})
    for (std::size_t k = 0; k < bins->size(); ++k)
      if (!std::isfinite((*bins)[k]) || (*bins)[k] < 0 || (k > 0 && (*bins)[k] <= (*bins)[k - 1]))
        throw InputError("", 0, "calibre bins must be finite, non-negative and increasing (lower edges)");
  if (!a.bins_voxels.empty()) opt.bins_voxels = a.bins_voxels;
  opt.bins_mm = a.bins_mm;
  const Json j = scoreCase(a.prediction, a.sample, opt);
  if (a.out.empty()) std::cout << j.dump(2) << "\n";
  else writeTextFile(a.out, [&](std::ostream& o) { o << j.dump(2) << "\n"; });
  if (!a.csv.empty()) writeTextFile(a.csv, [&](std::ostream& o) { writeCsv(o, j); });
  if (!a.common.quiet) {
    const Json& ov = j["overlap"];
    std::cerr << "Dice " << number(ov["dice"]) << ", HD95 " << number(j["surface"]["hd95_mm"]) << " mm, centreline recall "
              << number(j["centreline"]["recall"]) << "\n";
  }
  return 0;
}

}  // namespace angiosynth::cli
