// Benchmarks: the shipped noise ladder's Dice falls rung by rung for every baseline (and a
// baseline's mean Dice is what NumPy computes from its masks), a run gives the same bytes on one
// thread or two, resumes without redoing anything and scores a user's predictions beside the
// baselines, bad benchmark files name file
// and line, overrides reach the samples, and the report renders in headless Chromium with
// nothing fetched.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <map>
#include <sstream>

#include <nlohmann/json.hpp>

#include "benchmark/benchmark.hpp"
#include "cli_run.hpp"
#include "core/error.hpp"
#include "degrade/profile.hpp"
#include "test_support.hpp"

namespace angiosynth {
namespace {

namespace fs = std::filesystem;

const fs::path kShipped = test::sourceDir() / "examples" / "benchmarks";

// results.csv as rows of named fields.
std::vector<std::map<std::string, std::string>> readCsv(const fs::path& file) {
  std::ifstream in(file);
  std::string line;
  std::getline(in, line);
  std::vector<std::string> header;
  std::stringstream hs(line);
  for (std::string f; std::getline(hs, f, ',');) header.push_back(f);
  std::vector<std::map<std::string, std::string>> rows;
  while (std::getline(in, line)) {
    std::map<std::string, std::string> row;
    std::stringstream ls(line);
    std::size_t k = 0;
    for (std::string f; std::getline(ls, f, ',') && k < header.size(); ++k) row[header[k]] = f;
    rows.push_back(row);
  }
  return rows;
}

// A benchmark small enough for a test: the shipped VascuSynth-style dataset with 40 terminals
// and two cases per rung, one ladder of two noise levels.
fs::path writeSmallBenchmark(const fs::path& dir, const std::string& ladder_extra = "") {
  std::ofstream(dir / "bench.toml") << "[benchmark]\n"
                                       "title = \"small\"\n"
                                       "dataset = \""
                                    << (kShipped / "vascusynth_dataset.toml").string()
                                    << "\"\n"
                                       "samples = 2\n"
                                       "methods = [\"otsu\", \"frangi\"]\n"
                                       "set = {\"tree.terminals\" = 40}\n"
                                       "\n"
                                       "[[ladder]]\n"
                                       "name = \"noise\"\n"
                                       "key = \"profile.gaussian.sigma\"\n"
                                       "values = [5, 60]\n"
                                    << ladder_extra;
  return dir / "bench.toml";
}

TEST(Benchmark, ShippedNoiseLadderDiceFallsForEveryBaseline) {
  const fs::path dir = freshTestDir("angiosynth_bench_");
  const ::Run r = run(
      "benchmark '" + (kShipped / "vascusynth_noise_bifurcations.toml").string() + "' --ladders noise --set dataset.samples=3 --out out --threads 2",
      dir);
  ASSERT_EQ(r.code, 0) << r.err;
  const auto rows = readCsv(dir / "out" / "results.csv");
  std::map<std::string, std::vector<double>> dice;
  for (const auto& row : rows) {
    EXPECT_EQ(row.at("ladder"), "noise");
    EXPECT_EQ(row.at("cases"), "3");
    dice[row.at("method")].push_back(std::stod(row.at("dice")));
  }
  ASSERT_EQ(dice.size(), 8u);  // four baselines by their rule and at their tuned threshold
  for (const auto& [method, d] : dice) {
    ASSERT_EQ(d.size(), 6u) << method;
    for (std::size_t k = 1; k < d.size(); ++k) EXPECT_LT(d[k], d[k - 1]) << method << ": rung " << k;
    EXPECT_GT(d.front() - d.back(), 0.1) << method << ": noise σ 0 to 120 costs little";
  }
  // The rule's threshold (2 % of the maximum) is among the tuned ones' candidates: tuning can
  // only gain.
  for (const char* method : {"frangi", "sato", "jerman"})
    for (std::size_t k = 0; k < 6; ++k) EXPECT_GE(dice[std::string(method) + "-tuned"][k], dice[method][k] - 1e-9) << method << " rung " << k;
  // The tuning's own Dice at the share it chose is the scored Dice of the masks it made.
  for (const char* method : {"otsu", "frangi", "sato", "jerman"})
    for (const char* rung : {"00", "03", "05"}) {
      const auto j = nlohmann::json::parse(slurp(dir / "out" / "noise" / rung / "scores" / (std::string(method) + "-tuned.json")));
      const auto& fractions = j["tuning"]["fractions"];
      const std::size_t best = std::find(fractions.begin(), fractions.end(), j["tuned_fraction"]) - fractions.begin();
      ASSERT_LT(best, fractions.size());
      EXPECT_NEAR(j["tuning"]["mean_dice"][best].get<double>(), j["results"]["summary"]["dice"]["mean"].get<double>(), 1e-12)
          << method << " " << rung;
    }
  // The mean Dice of a rung, recomputed by NumPy from the baseline's masks and the exact truth.
  const std::string out = debianPython(R"(
import glob, os, nibabel as nib, numpy as np
rung = 'out/noise/02'
ds = glob.glob(rung + '/Dataset*')[0]
d = []
for p in sorted(glob.glob(rung + '/predictions/frangi/*.nii.gz')):
    case = os.path.basename(p)[:-7]
    pred = nib.load(p).get_fdata() > 0
    truth = nib.load(f'{ds}/groundtruth/{case}/mask.nii.gz').get_fdata() > 0
    d.append(2 * (pred & truth).sum() / (pred.sum() + truth.sum()))
print('dice', len(d), np.mean(d))
)",
                                       dir);
  std::istringstream in(out.substr(out.find("dice")));
  std::string word;
  int cases = 0;
  double mean = 0;
  in >> word >> cases >> mean;
  EXPECT_EQ(cases, 3) << out;
  EXPECT_NEAR(mean, dice["frangi"][2], 1e-5) << out;
}

TEST(Benchmark, ResumesWithoutRedoingAndScoresYourPredictionsBesideTheBaselines) {
  const fs::path dir = freshTestDir("angiosynth_bench_");
  const fs::path spec = writeSmallBenchmark(dir);
  ASSERT_EQ(run("benchmark bench.toml --out out --threads 2", dir).code, 0);
  const std::string csv = slurp(dir / "out" / "results.csv");
  // One thread: the same scores and masks, byte for byte.
  ASSERT_EQ(run("benchmark bench.toml --out one_thread --threads 1", dir).code, 0);
  EXPECT_EQ(slurp(dir / "one_thread" / "results.csv"), csv);
  for (const auto& f : fs::directory_iterator(dir / "out" / "noise" / "01" / "predictions" / "frangi"))
    EXPECT_EQ(slurp(f.path()), slurp(dir / "one_thread" / "noise" / "01" / "predictions" / "frangi" / f.path().filename())) << f.path();
  // In two shards (each rung's samples split), then scored once: the same bytes again.
  for (const char* shard : {"0/2", "1/2"}) {
    const ::Run part = runPrinted(std::string("benchmark bench.toml --out sharded --shard ") + shard, dir);
    ASSERT_EQ(part.code, 0) << part.err;
    EXPECT_NE(part.err.find("when every shard is done"), std::string::npos) << part.err;
    EXPECT_FALSE(fs::exists(dir / "sharded" / "results.csv"));
  }
  const ::Run joined = runPrinted("benchmark bench.toml --out sharded --resume", dir);
  ASSERT_EQ(joined.code, 0) << joined.err;
  EXPECT_NE(joined.err.find("0 samples generated, 4 kept"), std::string::npos) << joined.err;
  EXPECT_EQ(slurp(dir / "sharded" / "results.csv"), csv);
  // Into the same directory: refused without --resume; with it, nothing is made again.
  const ::Run again = run("benchmark bench.toml --out out", dir);
  EXPECT_EQ(again.code, 2);
  EXPECT_NE(again.err.find("is not empty; add --resume"), std::string::npos) << again.err;
  const ::Run resumed = runPrinted("benchmark bench.toml --out out --resume", dir);
  ASSERT_EQ(resumed.code, 0) << resumed.err;
  EXPECT_NE(resumed.err.find("0 samples generated, 4 kept, 0 failed; 0 cases segmented"), std::string::npos) << resumed.err;
  EXPECT_EQ(slurp(dir / "out" / "results.csv"), csv);
  // A user's method: here Otsu's masks under another name, so its rows must equal Otsu's.
  for (const char* rung : {"00", "01"}) {
    fs::create_directories(dir / "mine" / "noise" / rung);
    for (const auto& f : fs::directory_iterator(dir / "out" / "noise" / rung / "predictions" / "otsu"))
      fs::copy_file(f.path(), dir / "mine" / "noise" / rung / f.path().filename());
  }
  ASSERT_EQ(run("benchmark bench.toml --out out --resume --predictions mine=mine", dir).code, 0);
  const auto rows = readCsv(dir / "out" / "results.csv");
  ASSERT_EQ(rows.size(), 6u);
  for (const char* rung : {"00", "01"}) {
    std::map<std::string, std::string> otsu, mine;
    for (const auto& row : rows) {
      if (row.at("rung") != rung) continue;
      if (row.at("method") == "otsu") otsu = row;
      if (row.at("method") == "mine") mine = row;
    }
    ASSERT_FALSE(mine.empty()) << rung;
    EXPECT_EQ(mine.at("baseline"), "0");
    for (const char* column : {"dice", "cldice", "thin_vessel_recall", "hd95_mm", "b0_error"}) EXPECT_EQ(mine.at(column), otsu.at(column)) << column;
  }
  EXPECT_NE(slurp(dir / "out" / "report.html").find("mine (yours)"), std::string::npos);
  // A name taken by a baseline is refused.
  const ::Run clash = run("benchmark bench.toml --out out --resume --predictions frangi=mine", dir);
  EXPECT_EQ(clash.code, 2);
  EXPECT_NE(clash.err.find("is a baseline's"), std::string::npos) << clash.err;
}

TEST(Benchmark, OverridesReachTheSamplesAndTheirHashes) {
  const fs::path dir = freshTestDir("angiosynth_bench_");
  const fs::path spec = writeSmallBenchmark(dir);
  const BenchmarkSpec b = readBenchmarkSpec(spec);
  const DatasetSpec low = rungDataset(b, b.ladders[0], 0), high = rungDataset(b, b.ladders[0], 1);
  EXPECT_EQ(low.samples, 2);
  EXPECT_NE(low.sha256, high.sha256);
  const ResolvedSample a = resolveSample(low, 0), c = resolveSample(high, 0);
  EXPECT_EQ(a.toml, c.toml);  // the trees are the same; only the image differs
  EXPECT_NE(a.sha256, c.sha256);
  EXPECT_NE(a.toml.find("terminals = 40"), std::string::npos) << a.toml;
  const Profile p = sampleProfile(high, a.profile);
  ASSERT_EQ(p.effects.size(), 1u);
  EXPECT_EQ(p.effects[0].params.at("sigma").components[0].lo.value, 60);
  // The same override through `dataset --set`, recorded in spec.json and checked on resume.
  ASSERT_EQ(run("dataset '" + (kShipped / "vascusynth_dataset.toml").string() +
                    "' --out raw --set dataset.samples=1 --set tree.terminals=20 --set profile.gaussian.sigma=60",
                dir)
                .code,
            0);
  EXPECT_NE(slurp(dir / "raw" / "Dataset910_VascuSynthLadder" / "spec.json").find("profile.gaussian.sigma"), std::string::npos);
  const ::Run changed = run(
      "dataset '" + (kShipped / "vascusynth_dataset.toml").string() + "' --out raw --resume --set dataset.samples=1 --set tree.terminals=20", dir);
  EXPECT_EQ(changed.code, 2);
  EXPECT_NE(changed.err.find("changed: profile.gaussian.sigma (removed)"), std::string::npos) << changed.err;
}

TEST(Benchmark, BadFilesNameFileLineAndWhatIsAllowed) {
  const fs::path dir = freshTestDir("angiosynth_bench_");
  struct Case {
    std::string ladder_extra, expect;
  };
  const std::vector<Case> cases = {
      {"labels = [\"a\"]\n", "bench.toml:12: labels needs one text per value (2)"},
      {"colour = 1\n", "bench.toml:12: unknown key 'colour' in [[ladder]]; allowed: key, labels, name, set, title, values"},
      {"[[ladder]]\nname = \"bad\"\nkey = \"profile.gausian.sigma\"\nvalues = [1, 2]\n",
       "bench.toml:12: ladder bad, rung 00 (profile.gausian.sigma = 1): profile.gausian.sigma: the profile vascusynth has no effect 'gausian'"},
      {"[[ladder]]\nname = \"bad\"\nkey = \"tree.terminals\"\nvalues = [1, \"many\"]\n", "ladder bad, rung 01 (tree.terminals = 'many')"},
  };
  for (const auto& c : cases) {
    fs::remove_all(dir / "case");
    fs::create_directories(dir / "case");
    writeSmallBenchmark(dir / "case", c.ladder_extra);
    const ::Run r = run("benchmark bench.toml --out out", dir / "case");
    EXPECT_EQ(r.code, 2) << c.ladder_extra;
    EXPECT_NE(r.err.find(c.expect), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "case" / "out")) << "nothing is written for a bad file";
  }
  writeSmallBenchmark(dir);
  const ::Run r = run("benchmark bench.toml --out out --ladders noise_level", dir);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("no ladder named 'noise_level'; allowed: noise"), std::string::npos) << r.err;
}

// The report in a real browser: Chromium renders the page (curves in the methods' colours,
// thumbnails in many greys), and the page names no resource outside itself.
TEST(Benchmark, ReportRendersInHeadlessChromiumWithNothingFetched) {
  const fs::path dir = freshTestDir("angiosynth_bench_");
  writeSmallBenchmark(dir);
  ASSERT_EQ(run("benchmark bench.toml --out out", dir).code, 0);
  const std::string html = slurp(dir / "out" / "report.html");
  for (const char* external : {"src=\"http", "href=", "url(", "<script", "@import", "<link"})
    EXPECT_EQ(html.find(external), std::string::npos) << external;
  std::size_t at = 0;
  int thumbnails = 0;
  while ((at = html.find("src=\"data:image/png;base64,", at + 1)) != std::string::npos) ++thumbnails;
  EXPECT_EQ(thumbnails, 2);
  const std::string shot = (dir / "shot.png").string();
  const std::string cmd = "chromium --headless --no-sandbox --disable-gpu --hide-scrollbars --window-size=1200,1400 --screenshot='" + shot +
                          "' 'file://" + (dir / "out" / "report.html").string() + "' >/dev/null 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << "chromium (Debian's package) must be installed: scripts/install-deps.sh";
  const std::string out = debianPython(R"(
from PIL import Image
im = Image.open('shot.png').convert('RGB')
px = list(im.getdata())
orange = sum(1 for r, g, b in px if abs(r - 0xD5) < 12 and abs(g - 0x5E) < 12 and b < 20)
blue = sum(1 for r, g, b in px if r < 15 and abs(g - 0x72) < 12 and abs(b - 0xB2) < 12)
greys = len({r for r, g, b in px if r == g == b})
print('size', im.size[0], im.size[1], 'orange', orange, 'blue', blue, 'greys', greys)
)",
                                       dir);
  std::istringstream in(out.substr(out.find("size")));
  std::string w;
  int width = 0, height = 0, orange = 0, blue = 0, greys = 0;
  in >> w >> width >> height >> w >> orange >> w >> blue >> w >> greys;
  EXPECT_EQ(width, 1200) << out;
  EXPECT_EQ(height, 1400) << out;
  EXPECT_GT(orange, 200) << "frangi's curve (Okabe-Ito vermillion) is drawn: " << out;
  EXPECT_GT(blue, 200) << "otsu's curve is drawn: " << out;
  EXPECT_GT(greys, 100) << "the thumbnails are drawn: " << out;
}

}  // namespace
}  // namespace angiosynth
