// Running a benchmark: every rung's dataset, each baseline's masks and scores (kept and reused
// while the rung's samples and the baseline's options are unchanged), the user's predictions'
// scores, then results.csv, benchmark.json and report.html.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <optional>

#include "angiosynth/version.hpp"
#include "benchmark/benchmark.hpp"
#include "core/error.hpp"
#include "dataset/manifest.hpp"
#include "dataset/run_dataset.hpp"
#include "files/atomic_file.hpp"
#include "files/output_guard.hpp"
#include "io/nifti_reader.hpp"
#include "io/volume_writers.hpp"

namespace angiosynth {
namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

namespace {

const double kNaN = std::numeric_limits<double>::quiet_NaN();

Json readJsonFile(const fs::path& p) {
  std::ifstream in(p);
  Json j = Json::parse(in, nullptr, /*allow_exceptions=*/false);
  return j.is_discarded() ? Json() : j;
}

Json segmentOptionsJson(const SegmentOptions& o) {
  return Json{{"sigmas_mm", o.sigmas_mm},
              {"bright", o.bright},
              {"alpha", o.alpha},
              {"beta", o.beta},
              {"gamma", o.gamma},
              {"tau", o.tau},
              {"threshold_fraction", o.threshold_fraction}};
}

double summaryValue(const Json& results, const char* metric, const char* stat) {
  const Json& s = results.value("summary", Json::object());
  if (!s.contains(metric) || !s[metric].is_object() || !s[metric].contains(stat) || !s[metric][stat].is_number()) return kNaN;
  return s[metric][stat].get<double>();
}

// One row from a `score --dataset` result: the summary's means, and recall by calibre pooled over
// the cases' centreline voxels (each bin's recall weighted by its voxels).
BenchmarkRow rowOf(const Json& results) {
  BenchmarkRow r;
  r.cases = results.value("cases", std::int64_t(0));
  r.dice = summaryValue(results, "dice", "mean");
  r.dice_sd = summaryValue(results, "dice", "sd");
  r.cldice = summaryValue(results, "cldice", "mean");
  r.cldice_sd = summaryValue(results, "cldice", "sd");
  r.hd95_mm = summaryValue(results, "hd95_mm", "mean");
  r.precision = summaryValue(results, "precision", "mean");
  r.recall = summaryValue(results, "recall", "mean");
  r.centreline_recall = summaryValue(results, "centreline_recall", "mean");
  r.b0_error = summaryValue(results, "b0_error", "mean");
  const Json& aggregates = results.value("aggregates", Json::object());
  const Json classes = aggregates.contains("per_class") ? aggregates["per_class"].value("classes", Json::object()) : Json::object();
  if (classes.size() > 1)
    for (const auto& [name, c] : classes.items())
      r.class_recall.emplace_back(name,
                                  c.contains("recall") && c["recall"].value("mean", Json()).is_number() ? c["recall"]["mean"].get<double>() : kNaN);
  std::vector<double> hit, total;
  double thin_hit = 0, thin_total = 0;
  for (const auto& c : results.value("per_case", Json::array())) {
    const Json& bins = c.value("calibre", Json::array());
    if (!bins.is_array()) continue;
    for (std::size_t b = 0; b < bins.size(); ++b) {
      const Json& bin = bins[b];
      const double lower = bin["radius_voxels"][0].get<double>();
      const bool below_voxel = bin["radius_voxels"][1].is_number() && bin["radius_voxels"][1].get<double>() <= 1.0;
      if (hit.size() <= b) {
        hit.resize(b + 1, 0), total.resize(b + 1, 0);
        r.calibre_lower.resize(b + 1, lower);
      }
      const double n = bin.value("centreline_voxels", 0.0);
      if (n <= 0 || !bin["recall"].is_number()) continue;
      hit[b] += n * bin["recall"].get<double>();
      total[b] += n;
      if (below_voxel) thin_hit += n * bin["recall"].get<double>(), thin_total += n;
    }
  }
  for (std::size_t b = 0; b < hit.size(); ++b) r.calibre_recall.push_back(total[b] > 0 ? hit[b] / total[b] : kNaN);
  r.thin_recall = thin_total > 0 ? thin_hit / thin_total : kNaN;
  return r;
}

// The maximum projection of a case's image along z, its grey range from the 0.5th to the 99.95th
// percentile (a few bright voxels of noise or bone do not grey out the vessels); dark vessels
// are projected as the minimum.
std::string thumbnail(const fs::path& image, bool bright, std::uint64_t memory_limit) {
  NiftiVolume v = readNiftiVolume(image, memory_limit, 8, "image");
  if (!bright)
    for (auto& x : v.values.data) x = -x;
  const auto& d = v.values.grid.dims;
  std::vector<float> mip(std::size_t(d[0]) * d[1], -std::numeric_limits<float>::infinity());
  for (std::int64_t k = 0; k < d[2]; ++k)
    for (std::int64_t j = 0; j < d[1]; ++j)
      for (std::int64_t i = 0; i < d[0]; ++i) {
        float& m = mip[std::size_t(j) * d[0] + i];
        m = std::max(m, v.values.at(i, j, k));
      }
  std::vector<float> sorted = mip;
  std::sort(sorted.begin(), sorted.end());
  const double lo = sorted[std::size_t(0.005 * (sorted.size() - 1))], hi = sorted[std::size_t(0.9995 * (sorted.size() - 1))];
  return encodePng(maximumProjection(v.values, 2, lo, hi > lo ? hi : lo + 1));
}

// Candidate thresholds of the tuned baselines, as shares of a response's range: log-spaced
// where vesselness thresholds live (1e-4 … 1), linear across the range for the image (Otsu).
const std::vector<double> kTunedFractions = [] {
  std::vector<double> f;
  for (int k = 0; k <= 48; ++k) f.push_back(std::pow(10.0, -4.0 + 4.0 * k / 48.0));
  for (int k = 1; k < 50; ++k) f.push_back(k / 50.0);
  std::sort(f.begin(), f.end());
  f.erase(std::unique(f.begin(), f.end()), f.end());
  return f;
}();

// Dice against `truth > 0` (the ignore label's voxels left out) of the mask segment() makes at
// the threshold lo + f (hi - lo), for every candidate f: for the image (Otsu) voxels above it,
// lo its minimum; for vesselness voxels of positive response at or above it (in single
// precision, as segment() compares), lo = 0.
struct DiceCurve {
  double lo = 0, hi = 0;
  std::vector<double> dice;
};
double tunedThreshold(const DiceCurve& c, double fraction, bool image) {
  const double t = c.lo + fraction * (c.hi - c.lo);
  return image ? t : double(float(t));
}
DiceCurve diceCurve(const Volume<float>& response, const Volume<float>& truth, std::optional<int> ignore, bool image) {
  DiceCurve c;
  const auto& r = response.data;
  c.hi = *std::max_element(r.begin(), r.end());
  c.lo = image ? *std::min_element(r.begin(), r.end()) : 0.0;
  std::vector<double> thresholds;
  for (double f : kTunedFractions) thresholds.push_back(tunedThreshold(c, f, image));
  // Each voxel counts in the bin of how many thresholds it passes; threshold f is passed by the
  // voxels of bins f + 1 and above.
  std::vector<std::int64_t> passing(thresholds.size() + 1, 0), hits(thresholds.size() + 1, 0);
  std::int64_t positives = 0;
  for (std::size_t i = 0; i < r.size(); ++i) {
    if (ignore && truth.data[i] == float(*ignore)) continue;
    const bool vessel = truth.data[i] > 0;
    positives += vessel;
    const double v = r[i];
    std::size_t bin = 0;
    if (image)
      bin = std::lower_bound(thresholds.begin(), thresholds.end(), v) - thresholds.begin();  // thresholds below v
    else if (v > 0)
      bin = std::upper_bound(thresholds.begin(), thresholds.end(), v) - thresholds.begin();  // thresholds at or below v
    ++passing[bin];
    hits[bin] += vessel;
  }
  std::int64_t p = 0, tp = 0;
  c.dice.assign(thresholds.size(), 0.0);
  for (std::size_t f = thresholds.size(); f-- > 0;) {
    p += passing[f + 1];
    tp += hits[f + 1];
    c.dice[f] = p + positives > 0 ? 2.0 * double(tp) / double(p + positives) : 1.0;
  }
  return c;
}

std::vector<std::string> caseIds(const fs::path& dataset_dir, std::int64_t samples) {
  std::vector<std::string> ids;
  for (const auto& [i, e] : readManifests(dataset_dir, samples))
    if (e.value("status", std::string()) == "ok") ids.push_back(e["id"].get<std::string>());
  return ids;
}

}  // namespace

BenchmarkSummary runBenchmark(const BenchmarkSpec& spec, const fs::path& out, const BenchmarkOptions& opt) {
  const auto t0 = std::chrono::steady_clock::now();
  const auto say = [&](const std::string& m) {
    if (opt.progress) opt.progress(m);
  };
  BenchmarkSummary sum;
  checkOutputPath(out, {spec.file, spec.dataset}, "--out");
  std::error_code ec;
  if (fs::exists(out, ec) && !fs::is_empty(out, ec) && !opt.resume && opt.shards == 1)
    throw InputError(
        out.string(), 0,
        "is not empty; add --resume to continue an earlier run of this benchmark there (verified samples and unchanged scores are kept), "
        "or choose another --out");
  for (const auto& p : opt.predictions) {
    if (std::find(spec.methods.begin(), spec.methods.end(), p.name) != spec.methods.end())
      throw InputError("--predictions", 0, "the name " + p.name + " is a baseline's; give your method another name");
    if (!fs::is_directory(p.dir)) throw InputError(p.dir.string(), 0, "no such directory of predictions (--predictions " + p.name + "=DIR)");
  }
  fs::create_directories(out);
  std::vector<BenchmarkThumbnail> thumbnails;
  std::size_t rungs = 0, done_rungs = 0;
  for (const auto& l : spec.ladders) rungs += l.values.size();
  for (const auto& l : spec.ladders)
    for (std::size_t k = 0; k < l.values.size(); ++k) {
      ++done_rungs;
      const std::string where = l.name + " " + l.labels[k] + " (rung " + std::to_string(done_rungs) + " of " + std::to_string(rungs) + ")";
      const DatasetSpec ds = rungDataset(spec, l, k);
      const fs::path rung_dir = out / l.name / l.rungDir(k);
      DatasetSelection sel;
      sel.end = ds.samples;
      sel.shard = opt.shard;
      sel.shards = opt.shards;
      if (opt.shards > 1) sel.part = "shard-" + std::to_string(opt.shard) + "-of-" + std::to_string(opt.shards);
      DatasetRunOptions dopt;
      dopt.resume = true;  // the benchmark's own directory (checked above): verified samples are kept
      dopt.regenerate_changed = opt.regenerate_changed;
      dopt.memory_limit = opt.memory_limit;
      dopt.command_line = opt.command_line;
      const DatasetRunReport rep = runDataset(ds, rung_dir, sel, dopt);
      sum.samples_generated += rep.generated;
      sum.samples_skipped += rep.skipped;
      sum.samples_failed += rep.failed;
      say(where + ": " + std::to_string(rep.generated) + " samples generated, " + std::to_string(rep.skipped) + " kept");
      if (opt.shards > 1) continue;
      const DatasetCheck check = finalizeDataset(rep.dir);
      if (!check.problems.empty())
        throw InputError(rep.dir.string(), 0,
                         check.problems.front() + " (" + std::to_string(check.problems.size()) + " problems); run the benchmark again with --resume");
      const std::vector<std::string> ids = caseIds(rep.dir, ds.samples);
      if (ids.empty()) throw InputError(rep.dir.string(), 0, "holds no finished sample to score");
      const std::string inputs_key = sha256File(rep.dir / "manifest.jsonl");
      thumbnails.push_back({l.name, l.rungDir(k),
                            thumbnail(rep.dir / "imagesTr" / (ids.front() + "_0000.nii.gz"), spec.segment.bright, opt.memory_limit), l.labels[k]});
      const auto readCase = [&](const std::string& id, const SegmentOptions& o) {
        return readNiftiVolume(rep.dir / "imagesTr" / (id + "_0000.nii.gz"), opt.memory_limit, 9 + segmentBytesPerVoxel(o), "image");
      };
      const auto runSegment = [&](const Volume<float>& image, const SegmentOptions& o, SegmentSummary& ss, Volume<float>* response) {
        try {
          return segment(image, o, ss, response);
        } catch (const std::invalid_argument& e) { throw InputError(spec.file, 0, std::string("[segment]: ") + e.what()); }
      };
      const auto addRow = [&](const Json& results, const std::string& method, bool baseline, double seconds, double tuned_fraction = kNaN) {
        BenchmarkRow row = rowOf(results);
        row.tuned_fraction = tuned_fraction;
        row.ladder = l.name;
        row.rung = l.rungDir(k);
        row.label = l.labels[k];
        row.value = l.values[k];
        row.method = method;
        row.baseline = baseline;
        row.seconds_per_case = seconds;
        sum.rows.push_back(std::move(row));
      };
      ScoreOptions so;
      so.memory_limit = opt.memory_limit;
      DatasetScoreOptions select;
      select.truth = spec.truth;
      // One baseline's masks for every case (the rule's, or per case `threshold_of` on the
      // response), scored; kept while `key` is unchanged.
      // A baseline's scores from an earlier run, when made from the same inputs: its row added.
      const auto keptScores = [&](const std::string& name, const std::string& key) {
        const fs::path scores_file = rung_dir / "scores" / (name + ".json");
        const Json kept = fs::exists(scores_file) ? readJsonFile(scores_file) : Json();
        if (!kept.is_object() || kept.value("inputs_sha256", std::string()) != key || !kept.contains("results")) return false;
        addRow(kept["results"], name, true, kept.value("seconds_per_case", 0.0), kept.value("tuned_fraction", kNaN));
        return true;
      };
      const auto baseline = [&](const std::string& name, const SegmentOptions& o, const std::string& key, double tuned_fraction,
                                const std::function<double(std::size_t)>& threshold_of, const Json& tuning = Json()) {
        if (keptScores(name, key)) return;
        const fs::path scores_file = rung_dir / "scores" / (name + ".json");
        const fs::path pred_dir = rung_dir / "predictions" / name;
        fs::create_directories(pred_dir);
        double seconds = 0;
        for (std::size_t c = 0; c < ids.size(); ++c) {
          const NiftiVolume in = readCase(ids[c], o);
          SegmentOptions oc = o;
          if (threshold_of) oc.has_threshold = true, oc.threshold = threshold_of(c);
          SegmentSummary ss;
          const Volume<std::uint8_t> mask = runSegment(in.values, oc, ss, nullptr);
          seconds += ss.seconds;
          writeNiftiAtomically(pred_dir / (ids[c] + ".nii.gz"), viewOf(mask, true, "angiosynth segment " + o.method), &in.affine, true);
          ++sum.cases_segmented;
        }
        const DatasetScores scores = scoreDataset(rep.dir, pred_dir, so, select, {});
        fs::create_directories(scores_file.parent_path());
        const double per_case = seconds / double(ids.size());
        Json record{{"inputs_sha256", key}, {"method", name}, {"segment", segmentOptionsJson(o)}, {"seconds_per_case", per_case}};
        if (std::isfinite(tuned_fraction)) record["tuned_fraction"] = tuned_fraction;
        if (!tuning.is_null()) record["tuning"] = tuning;
        record["results"] = scores.results;
        writeFileAtomically(scores_file, record.dump(1) + "\n");
        addRow(scores.results, name, true, per_case, tuned_fraction);
        say(where + ": " + name + " mean Dice " + std::to_string(sum.rows.back().dice));
      };
      for (const auto& method : spec.methods) {
        SegmentOptions o = spec.segment;
        o.method = method;
        const std::string key = sha256Text(std::string(kVersion) + "\n" + inputs_key + "\n" + method + "\n" + segmentOptionsJson(o).dump() + "\n" +
                                           datasetTruthName(spec.truth));
        baseline(method, o, key, kNaN, {});
        if (!spec.tuned) continue;
        // The oracle: the share of each case's response range (one for the rung) whose
        // threshold gives the best mean Dice against the truth.
        const std::string tuned_key = sha256Text(key + "\ntuned threshold");
        const std::string tuned_name = method + "-tuned";
        if (keptScores(tuned_name, tuned_key)) continue;
        std::vector<double> mean_dice(kTunedFractions.size(), 0.0);
        std::vector<DiceCurve> curves(ids.size());
        for (std::size_t c = 0; c < ids.size(); ++c) {
          const NiftiVolume in = readCase(ids[c], o);
          SegmentSummary ss;
          Volume<float> response;
          runSegment(in.values, o, ss, &response);
          const TruthFiles truth = datasetCaseTruth(rep.dir, ids[c], spec.truth);
          const NiftiVolume t = readNiftiVolume(truth.mask, opt.memory_limit, 4 + 4, "truth");
          curves[c] = diceCurve(response, t.values, truth.ignore_value, o.method == "otsu");
          for (std::size_t f = 0; f < kTunedFractions.size(); ++f) mean_dice[f] += curves[c].dice[f] / double(ids.size());
          curves[c].dice.clear();
        }
        const std::size_t best = std::max_element(mean_dice.begin(), mean_dice.end()) - mean_dice.begin();
        const double fraction = kTunedFractions[best];
        const Json tuning{{"fractions", kTunedFractions}, {"mean_dice", mean_dice}};
        baseline(
            tuned_name, o, tuned_key, fraction, [&](std::size_t c) { return tunedThreshold(curves[c], fraction, o.method == "otsu"); }, tuning);
      }
      for (const auto& p : opt.predictions) {
        const fs::path dir = p.dir / l.name / l.rungDir(k);
        if (!fs::is_directory(dir)) {
          say(where + ": no predictions of " + p.name + " (" + dir.string() + ")");
          continue;
        }
        const DatasetScores scores = scoreDataset(rep.dir, dir, so, select, {});
        fs::create_directories(rung_dir / "scores");
        writeFileAtomically(rung_dir / "scores" / ("user-" + p.name + ".json"), Json{{"method", p.name}, {"results", scores.results}}.dump(1) + "\n");
        addRow(scores.results, p.name, false, 0);
        say(where + ": " + p.name + " mean Dice " + std::to_string(sum.rows.back().dice) + " over " + std::to_string(scores.scored.size()) +
            " cases");
      }
    }
  if (opt.shards > 1) {
    sum.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return sum;
  }
  sum.scored = true;
  sum.csv = out / "results.csv";
  sum.json = out / "benchmark.json";
  sum.report = out / "report.html";
  writeFileAtomically(sum.csv, benchmarkCsv(sum.rows));
  Json rows = Json::array();
  for (const auto& r : sum.rows) {
    Json class_recall = Json::object();
    for (const auto& [name, v] : r.class_recall) class_recall[name] = v;
    rows.push_back(Json{{"ladder", r.ladder},
                        {"rung", r.rung},
                        {"label", r.label},
                        {"value", r.value},
                        {"method", r.method},
                        {"baseline", r.baseline},
                        {"cases", r.cases},
                        {"dice", r.dice},
                        {"dice_sd", r.dice_sd},
                        {"cldice", r.cldice},
                        {"cldice_sd", r.cldice_sd},
                        {"thin_vessel_recall", r.thin_recall},
                        {"class_recall", class_recall},
                        {"calibre_lower_voxels", r.calibre_lower},
                        {"calibre_recall", r.calibre_recall},
                        {"hd95_mm", r.hd95_mm},
                        {"precision", r.precision},
                        {"recall", r.recall},
                        {"centreline_recall", r.centreline_recall},
                        {"b0_error", r.b0_error},
                        {"tuned_fraction", r.tuned_fraction},
                        {"seconds_per_case", r.seconds_per_case}});
  }
  writeFileAtomically(sum.json, Json{{"tool", {{"name", "angiosynth"}, {"version", kVersion}}},
                                     {"benchmark", spec.file},
                                     {"spec", spec.text},
                                     {"dataset", spec.dataset.string()},
                                     {"truth", datasetTruthName(spec.truth)},
                                     {"command_line", opt.command_line},
                                     {"rows", rows}}
                                        .dump(1) +
                                    "\n");
  writeFileAtomically(sum.report, benchmarkReportHtml(spec, sum, thumbnails, opt.command_line));
  sum.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return sum;
}

}  // namespace angiosynth
