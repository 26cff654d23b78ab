// Scoring: overlap and surface distances against a brute-force
// computation on hand-made volumes (shifted spheres, anisotropic voxels), the empty-mask
// conventions, the NumPy percentile, and `angiosynth score` on a generated sample with a
// prediction that misses every vessel thinner than one voxel.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <fstream>
#include <map>

#include "cli_run.hpp"
#include "test_support.hpp"
#include "io/nifti_reader.hpp"
#include "io/volume_writers.hpp"
#include "score/betti.hpp"
#include "score/calibre_plot.hpp"
#include "score/case_scores.hpp"
#include "score/dataset_scores.hpp"
#include "score/measures.hpp"
#include "score/metric.hpp"
#include "score/skeleton.hpp"

namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;
using namespace angiosynth;

VolumeGrid grid(int n, const Vec3& spacing) {
  VolumeGrid g;
  g.dims = {n, n, n};
  g.spacing_mm = spacing;
  return g;
}

// A ball of radius r (mm) around c (mm).
Volume<std::uint8_t> ball(const VolumeGrid& g, const Vec3& c, double r) {
  Volume<std::uint8_t> v(g);
  for (int k = 0; k < g.dims[2]; ++k)
    for (int j = 0; j < g.dims[1]; ++j)
      for (int i = 0; i < g.dims[0]; ++i) v.at(i, j, k) = distance(g.centre(i, j, k), c) <= r;
  return v;
}

// Border voxels listed by brute force: a voxel of v whose 6 face neighbours are not all in v.
std::vector<Vec3> border(const Volume<std::uint8_t>& v) {
  std::vector<Vec3> out;
  const auto& g = v.grid;
  const auto in = [&](int i, int j, int k) { return i >= 0 && j >= 0 && k >= 0 && i < g.dims[0] && j < g.dims[1] && k < g.dims[2] && v.at(i, j, k); };
  for (int k = 0; k < g.dims[2]; ++k)
    for (int j = 0; j < g.dims[1]; ++j)
      for (int i = 0; i < g.dims[0]; ++i)
        if (in(i, j, k) && !(in(i - 1, j, k) && in(i + 1, j, k) && in(i, j - 1, k) && in(i, j + 1, k) && in(i, j, k - 1) && in(i, j, k + 1)))
          out.push_back(g.centre(i, j, k));
  return out;
}

std::vector<double> directed(const std::vector<Vec3>& from, const std::vector<Vec3>& to) {
  std::vector<double> d;
  for (const auto& p : from) {
    double best = INFINITY;
    for (const auto& q : to) best = std::min(best, distance(p, q));
    d.push_back(best);
  }
  return d;
}

TEST(Score, PercentileIsNumpysLinearInterpolation) {
  std::vector<double> v;
  for (int i = 101; i >= 1; --i) v.push_back(i);
  EXPECT_DOUBLE_EQ(percentile95(v), 96.0);       // np.percentile(range(1, 102), 95)
  EXPECT_DOUBLE_EQ(percentile95({0, 10}), 9.5);  // np.percentile([0, 10], 95)
  EXPECT_DOUBLE_EQ(percentile95({3}), 3.0);
}

// Two balls of radius 6 mm, the prediction shifted by k voxels along x; isotropic and
// anisotropic voxels. Overlap by counting, distances against all pairs of border voxels.
TEST(Score, ShiftedSpheresMatchBruteForceOverlapAndSurfaceDistances) {
  for (const Vec3 spacing : {Vec3(1, 1, 1), Vec3(0.8, 1.0, 1.7)}) {
    for (int k : {0, 1, 3}) {
      const VolumeGrid g = grid(24, spacing);
      const Vec3 c = g.centre(11, 11, 11) + Vec3(0.3, 0.1, 0.2);
      const auto truth = ball(g, c, 6), pred = ball(g, c + Vec3(k * spacing.x, 0, 0), 6);
      std::int64_t tp = 0, fp = 0, fn = 0;
      for (std::size_t i = 0; i < truth.data.size(); ++i)
        tp += pred.data[i] && truth.data[i], fp += pred.data[i] && !truth.data[i], fn += !pred.data[i] && truth.data[i];
      const Json o = Json::parse(overlapScores(pred, truth, false).dump());
      EXPECT_DOUBLE_EQ(o["dice"].get<double>(), 2.0 * tp / (2.0 * tp + fp + fn));
      EXPECT_DOUBLE_EQ(o["jaccard"].get<double>(), double(tp) / double(tp + fp + fn));
      EXPECT_DOUBLE_EQ(o["precision"].get<double>(), double(tp) / double(tp + fp));
      EXPECT_DOUBLE_EQ(o["recall"].get<double>(), double(tp) / double(tp + fn));
      const auto bp = border(pred), bt = border(truth);
      const auto pt = directed(bp, bt), tp_ = directed(bt, bp);
      double hd = 0, sum = 0, sp = 0, st = 0, within = 0;
      const double tau = 1.0;
      for (double x : pt) hd = std::max(hd, x), sum += x, sp += x, within += x <= tau;
      for (double x : tp_) hd = std::max(hd, x), sum += x, st += x, within += x <= tau;
      const Json s = Json::parse(surfaceScores(pred, truth, tau, false).dump());
      ASSERT_EQ(s["border_voxels_prediction"].get<std::size_t>(), bp.size());
      EXPECT_NEAR(s["hd_mm"].get<double>(), hd, 1e-9) << k;
      EXPECT_NEAR(s["hd95_mm"].get<double>(), std::max(percentile95(pt), percentile95(tp_)), 1e-9);
      EXPECT_NEAR(s["assd_mm"].get<double>(), sum / double(bp.size() + bt.size()), 1e-9);
      EXPECT_NEAR(s["masd_mm"].get<double>(), 0.5 * (sp / double(bp.size()) + st / double(bt.size())), 1e-9);
      EXPECT_NEAR(s["nsd"].get<double>(), within / double(bp.size() + bt.size()), 1e-12);
      // A ball shifted along x: the farthest border voxel lies exactly the shift away.
      if (spacing.x == 1) { EXPECT_NEAR(s["hd_mm"].get<double>(), k, 1e-9); }
    }
  }
}

TEST(Score, EmptyMasksFollowTheWrittenConventions) {
  const VolumeGrid g = grid(10, Vec3(1, 1, 1));
  const Volume<std::uint8_t> none(g), some = ball(g, g.centre(5, 5, 5), 2);
  Json o = Json::parse(overlapScores(none, none, false).dump());
  EXPECT_EQ(o["dice"], 1.0);
  EXPECT_TRUE(o["precision"].is_null());
  EXPECT_EQ(Json::parse(overlapScores(none, none, true).dump())["dice"], 0.0);  // TopCoW
  o = Json::parse(overlapScores(none, some, false).dump());
  EXPECT_EQ(o["dice"], 0.0);
  EXPECT_EQ(o["recall"], 0.0);
  EXPECT_TRUE(o["precision"].is_null());
  Json s = Json::parse(surfaceScores(none, some, 1, false).dump());
  EXPECT_TRUE(s["hd95_mm"].is_null());
  EXPECT_EQ(s["nsd"], 0.0);
  s = Json::parse(surfaceScores(none, some, 1, true).dump());
  EXPECT_EQ(s["hd95_mm"], 90.0);
  s = Json::parse(surfaceScores(none, none, 1, false).dump());
  EXPECT_EQ(s["hd_mm"], 0.0);
  EXPECT_EQ(s["nsd"], 1.0);
}

class ScoreRun : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = freshTestDir("angiosynth_score_"); }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
  const fs::path src_ = ANGIOSYNTH_SOURCE_DIR;
};

// A prediction that is the truth mask less every voxel of a vessel thinner than one voxel: its
// calibre curve must drop below one voxel and stay at 1 above, and the thick vessels are all
// detected; a prediction on another grid is refused with a clear message and writes nothing.
TEST_F(ScoreRun, APredictionMissingTheThinVesselsShowsItInTheCalibreCurve) {
  std::ofstream(dir_ / "p.toml") << "seed = 3\n[domain]\ndemand_map = '" << (src_ / "demand_maps/vascusynth_rods_100.txt").string()
                                 << "'\nsupply_coefficients = [0.65, 0.34, 0.01, 7]\nvoxel_size = \"0.4 mm\"\n"
                                    "[tree]\nterminals = 300\nroot_voxel = [0, 50, 50]\n"
                                    "[physics]\nviscosity = \"3.6 mPa*s\"\nperfusion_pressure = \"13300 Pa\"\n"
                                    "terminal_pressure = \"8300 Pa\"\nperfusion_flow = \"8330 mm3/s\"\n"
                                    "[image]\nformats = [\"nifti\"]\n";
  ASSERT_EQ(run("generate p.toml --out s --quiet", dir_).code, 0);
  // Radius of each segment from edges.csv (id = segment id = instance label).
  std::map<long, double> radius;
  {
    std::ifstream in(dir_ / "s/edges.csv");
    std::string line;
    std::getline(in, line);
    while (std::getline(in, line)) {
      std::stringstream ss(line);
      std::string cell[5];
      for (auto& c : cell) std::getline(ss, c, ',');
      radius[std::stol(cell[0])] = std::stod(cell[4]);
    }
  }
  const NiftiVolume inst = readNiftiVolume(dir_ / "s/instances.nii.gz", 1ULL << 32, 4, "instances");
  const NiftiVolume mask = readNiftiVolume(dir_ / "s/mask.nii.gz", 1ULL << 32, 4, "mask");
  const double voxel = inst.values.grid.spacing_mm.x;
  Volume<std::uint8_t> pred(inst.values.grid);
  std::int64_t kept = 0, dropped = 0;
  for (std::size_t i = 0; i < pred.data.size(); ++i) {
    if (!(mask.values.data[i] > 0)) continue;
    const bool thick = radius[long(inst.values.data[i])] >= voxel;
    pred.data[i] = thick;
    kept += thick, dropped += !thick;
  }
  ASSERT_GT(kept, 500);
  ASSERT_GT(dropped, 500);
  writeNifti(dir_ / "pred.nii.gz", viewOf(pred, true, "test prediction"));
  const auto r = run("score pred.nii.gz s --out scores.json --csv scores.csv --quiet", dir_);
  ASSERT_EQ(r.code, 0) << r.err;
  const Json j = Json::parse(slurp(dir_ / "scores.json"));
  std::printf("[ measure  ] calibre recall %s\n", j["calibre"].dump().c_str());
  const Json& bins = j["calibre"];
  ASSERT_EQ(bins.size(), 5u);
  EXPECT_LT(bins[0]["recall"].get<double>(), 0.3) << bins.dump();   // radius < ½ voxel
  EXPECT_LT(bins[1]["recall"].get<double>(), 0.5) << bins.dump();   // ½ … 1 voxel
  EXPECT_GT(bins[2]["recall"].get<double>(), 0.95) << bins.dump();  // 1 … 2 voxels
  for (const auto& b : bins) {
    if (!b["truth_coverage"].is_null()) {
      EXPECT_EQ(b["truth_coverage"], 1.0);  // the mask holds every centreline voxel
    }
  }
  EXPECT_EQ(j["overlap"]["precision"], 1.0);
  EXPECT_NEAR(j["overlap"]["recall"].get<double>(), double(kept) / double(kept + dropped), 1e-12);
  const Json& lv = j["vessels"]["by_level"];
  ASSERT_GT(lv.size(), 3u);
  EXPECT_EQ(lv[0]["detected_rate"], 1.0);                       // the root vessel is thick
  EXPECT_LT(j["vessels"]["detected_rate"].get<double>(), 0.5);  // most vessels are thin
  const std::string csv = slurp(dir_ / "scores.csv");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 2) << csv;
  // Another grid: refused, nothing written.
  Volume<std::uint8_t> small(grid(10, Vec3(0.4, 0.4, 0.4)));
  writeNifti(dir_ / "small.nii.gz", viewOf(small, true, "wrong grid"));
  const auto bad = run("score small.nii.gz s --out bad.json", dir_);
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.err.find("small.nii.gz: the prediction has 10 x 10 x 10 voxels"), std::string::npos) << bad.err;
  EXPECT_FALSE(fs::exists(dir_ / "bad.json"));
  const auto again = run("score pred.nii.gz s --out scores.json", dir_);  // never replaces a file without --force
  EXPECT_EQ(again.code, 2);
  EXPECT_NE(again.err.find("exists; give --force"), std::string::npos) << again.err;
}

// The same numbers as SciPy (distance_transform_edt with the voxel spacing on the border sets,
// NumPy's percentile) on a generated sample scored with its clean image as the prediction.
TEST_F(ScoreRun, SurfaceAndOverlapAgreeWithScipy) {
  std::ofstream(dir_ / "p.toml") << "seed = 4\n[domain]\nshape = \"sphere\"\nradius = \"6 mm\"\nvoxel_size = \"0.25 mm\"\n"
                                    "[tree]\nmethod = \"cco\"\nterminals = 200\n[image]\nformats = [\"nifti\"]\n";
  ASSERT_EQ(run("generate p.toml --out s --quiet", dir_).code, 0);
  ASSERT_EQ(run("score s/image.nii.gz s --out scores.json --quiet", dir_).code, 0);
  // A band of 3 mm: twelve voxels each way, measured by distance transform instead of neighbourhoods.
  ASSERT_EQ(run("score s/image.nii.gz s --out wide.json --boundary-width 3 --quiet", dir_).code, 0);
  const std::string out = debianPython(R"(
import json, numpy as np, nibabel as nib
from scipy import ndimage as ndi
p = np.asarray(nib.load('s/image.nii.gz').dataobj) > 0
t = np.asarray(nib.load('s/mask.nii.gz').dataobj) > 0
sp = nib.load('s/mask.nii.gz').header.get_zooms()
face = ndi.generate_binary_structure(3, 1)
border = lambda m: m & ~ndi.binary_erosion(m, face, border_value=0)
bp, bt = border(p), border(t)
a, b = ndi.distance_transform_edt(~bt, sampling=sp)[bp], ndi.distance_transform_edt(~bp, sampling=sp)[bt]
tp, fp, fn = (p & t).sum(), (p & ~t).sum(), (~p & t).sum()
tau = min(sp)
ref = [2 * tp / (2 * tp + fp + fn), max(a.max(), b.max()), max(np.percentile(a, 95), np.percentile(b, 95)),
       (a.sum() + b.sum()) / (len(a) + len(b)), 0.5 * (a.mean() + b.mean()), ((a <= tau).sum() + (b <= tau).sum()) / (len(a) + len(b))]
j = json.load(open('scores.json'))
s = j['surface']
# Boundary IoU: the inner bands by SciPy's distance transform of the padded masks, Cheng et al.'s
# default width; the boxes' shells as sets of voxels, as the TopCoW 2024 evaluation builds them.
d = 0.02 * np.sqrt(sum((n * h) ** 2 for n, h in zip(t.shape, sp)))
band = lambda m: m & (ndi.distance_transform_edt(np.pad(m, 1), sampling=sp)[1:-1, 1:-1, 1:-1] <= d)
Bp, Bt = band(p), band(t)
def shell(m, ratio):
    idx = np.argwhere(m)
    lo, hi = idx.min(0), idx.max(0)
    dist = [int(np.ceil((h - l + 1) * ratio)) for l, h in zip(lo, hi)]
    pts = set()
    for x in range(lo[0], hi[0] + 1):
        for y in range(lo[1], hi[1] + 1):
            for z in range(lo[2], hi[2] + 1):
                q = (x, y, z)
                if any(q[a] - lo[a] < dist[a] or hi[a] - q[a] < dist[a] for a in range(3)):
                    pts.add(q)
    return pts
sp_, st_ = shell(p, 0.2), shell(t, 0.2)
b = j['boundary_iou']
ref += [(Bp & Bt).sum() / (Bp | Bt).sum(), len(sp_ & st_) / len(sp_ | st_), b['band_width_mm']]
ours = [j['overlap']['dice'], s['hd_mm'], s['hd95_mm'], s['assd_mm'], s['masd_mm'], s['nsd'],
        b['boundary_iou'], b['bounding_box']['boundary_iou'], d]
d = 3
Bp, Bt = band(p), band(t)
ref.append((Bp & Bt).sum() / (Bp | Bt).sum())
ours.append(json.load(open('wide.json'))['boundary_iou']['boundary_iou'])
print('max_difference', max(abs(x - y) for x, y in zip(ref, ours)), 'fp', int(fp), 'biou', b['boundary_iou'], 'jaccard', j['overlap']['jaccard'])
)",
                                       dir_);
  double diff = 1, biou = 0, jaccard = 0;
  int fp = 0;
  ASSERT_EQ(std::sscanf(out.c_str(), "max_difference %lf fp %d biou %lf jaccard %lf", &diff, &fp, &biou, &jaccard), 4) << out;
  EXPECT_LT(diff, 1e-9) << out;
  EXPECT_GT(fp, 0) << out;  // not vacuous: the prediction differs from the truth
  EXPECT_LT(biou, 1) << out;
}

}  // namespace

namespace {

// `score --dataset`: every case of a dataset against its own image's truth (the warped labels
// and graph for the profile that warps, the mask where labelsTr holds the classes); labelsTr as
// predictions score Dice 1 everywhere, against the training label and the exact mask alike.
TEST_F(ScoreRun, DatasetModeScoresEveryCaseAgainstItsImagesTruth) {
  fs::copy_file(src_ / "tests/data/profile_warp.toml", dir_ / "profile_warp.toml");
  fs::copy_file(src_ / "tests/data/dataset_av.toml", dir_ / "spec.toml");
  ASSERT_EQ(run("dataset spec.toml --out raw --quiet", dir_).code, 0);
  const fs::path ds = dir_ / "raw/Dataset903_ArteryVeinTiny";
  fs::create_directories(dir_ / "pred");
  for (const auto& e : fs::directory_iterator(ds / "labelsTr")) fs::copy_file(e.path(), dir_ / "pred" / e.path().filename());
  const auto r = run("score --dataset raw/Dataset903_ArteryVeinTiny --predictions pred --truth exact --out all.json --csv all.csv --quiet", dir_);
  ASSERT_EQ(r.code, 0) << r.err;
  const Json j = Json::parse(slurp(dir_ / "all.json"));
  ASSERT_EQ(j["cases"], 3);
  EXPECT_EQ(j["truth"], "exact");
  EXPECT_NE(j["truth_is"].get<std::string>().find("exact mask"), std::string::npos) << j["truth_is"];
  EXPECT_EQ(j["summary"]["dice"]["mean"], 1.0);
  EXPECT_EQ(j["summary"]["hd_mm"]["max"], 0.0);
  int warped = 0;
  for (const auto& c : j["per_case"]) {
    EXPECT_EQ(c["centreline"]["recall"], 1.0) << c["case"];
    EXPECT_EQ(c["vessels"]["detected_rate"], 1.0) << c["case"];
    warped += c["truth"].get<std::string>().find("groundtruth") != std::string::npos &&
              fs::exists(ds / "groundtruth" / c["case"].get<std::string>() / "centerline_profile_warp.nii.gz");
  }
  EXPECT_GT(warped, 0);  // the spec's profile file warps: some case was scored against warped labels
  const std::string csv = slurp(dir_ / "all.csv");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 1 + 3 + 3) << csv;  // header, cases, mean/median/sd
  // Case names as the statistics' names, unquoted (RFC 4180 quotes only what needs it); every
  // number to six significant digits.
  EXPECT_NE(csv.find("\nArteryVeinTiny_0000,"), std::string::npos) << csv;
  EXPECT_EQ(csv.find('"'), std::string::npos) << csv;
  std::istringstream fields(csv);
  for (std::string field; std::getline(fields, field, ',');) {
    field = field.substr(0, field.find('\n'));
    if (field.empty() || !(std::isdigit(static_cast<unsigned char>(field[0])) || field[0] == '-')) continue;
    std::string mantissa = field.substr(0, field.find('e'));
    mantissa.erase(std::remove(mantissa.begin(), mantissa.end(), '.'), mantissa.end());
    mantissa.erase(0, mantissa.find_first_not_of("-0"));
    EXPECT_LE(mantissa.size(), 6u) << field;
  }
  // The default truth is the training label (labelsTr, here labelled by kind), named as such;
  // each class summarised over the cases, in JSON and CSV.
  ASSERT_EQ(run("score --dataset raw/Dataset903_ArteryVeinTiny --predictions pred --out train.json --class-csv classes.csv --quiet", dir_).code, 0);
  const Json t = Json::parse(slurp(dir_ / "train.json"));
  EXPECT_EQ(t["truth"], "training");
  EXPECT_NE(t["truth_is"].get<std::string>().find("training label"), std::string::npos) << t["truth_is"];
  EXPECT_EQ(t["summary"]["dice"]["mean"], 1.0);
  EXPECT_EQ(t["summary"]["class_avg_dice"]["mean"], 1.0);
  for (const char* kind : {"artery", "vein"}) {
    EXPECT_EQ(t["aggregates"]["per_class"]["classes"][kind]["cases_present"], 3) << kind;
    EXPECT_EQ(t["aggregates"]["per_class"]["classes"][kind]["dice"]["mean"], 1.0) << kind;
  }
  const std::string classes = slurp(dir_ / "classes.csv");
  EXPECT_EQ(classes.rfind("class,cases_present,dice_mean,dice_sd,", 0), 0u) << classes;
  EXPECT_NE(classes.find("\nartery,3,1,"), std::string::npos) << classes;
  EXPECT_NE(classes.find("\nvein,3,1,"), std::string::npos) << classes;
  EXPECT_NE(classes.find("\nclass average,3,1,"), std::string::npos) << classes;

  // A fold: the cases that have predictions are scored, the others named.
  fs::remove(dir_ / "pred/ArteryVeinTiny_0001.nii.gz");
  const auto fold = run("score --dataset raw/Dataset903_ArteryVeinTiny --predictions pred --out fold.json", dir_);
  ASSERT_EQ(fold.code, 0) << fold.err;
  const Json f = Json::parse(slurp(dir_ / "fold.json"));
  EXPECT_EQ(f["cases"], 2);
  EXPECT_EQ(f["missing_predictions"], Json::array({"ArteryVeinTiny_0001"}));
  EXPECT_NE(fold.err.find("no prediction for 1 of the 3 cases selected: ArteryVeinTiny_0001"), std::string::npos) << fold.err;
  // nnU-Net's splits: the validation cases of one fold.
  std::ofstream(dir_ / "splits_final.json") << R"([{"train": ["ArteryVeinTiny_0001", "ArteryVeinTiny_0002"], "val": ["ArteryVeinTiny_0000"]},
    {"train": ["ArteryVeinTiny_0000", "ArteryVeinTiny_0002"], "val": ["ArteryVeinTiny_0001"]},
    {"train": ["ArteryVeinTiny_0000", "ArteryVeinTiny_0001"], "val": ["ArteryVeinTiny_0002"]}])";
  ASSERT_EQ(
      run("score --dataset raw/Dataset903_ArteryVeinTiny --predictions pred --splits splits_final.json --fold 2 --out f2.json --quiet", dir_).code,
      0);
  const Json f2 = Json::parse(slurp(dir_ / "f2.json"));
  EXPECT_EQ(f2["cases"], 1);
  EXPECT_EQ(f2["per_case"][0]["case"], "ArteryVeinTiny_0002");
  EXPECT_EQ(f2["missing_predictions"], Json::array());
  const auto none = run("score --dataset raw/Dataset903_ArteryVeinTiny --predictions pred --splits splits_final.json --fold 1 --out f1.json", dir_);
  EXPECT_EQ(none.code, 2);
  EXPECT_NE(none.err.find("holds no prediction for the validation cases of fold 1"), std::string::npos) << none.err;
  EXPECT_FALSE(fs::exists(dir_ / "f1.json"));
  const auto bad_fold = run("score --dataset raw/Dataset903_ArteryVeinTiny --predictions pred --splits splits_final.json --fold 3", dir_);
  EXPECT_EQ(bad_fold.code, 2);
  EXPECT_NE(bad_fold.err.find("has folds 0 to 2; --fold 3 is not one"), std::string::npos) << bad_fold.err;
  // One case of the dataset.
  const auto one =
      run("score pred/ArteryVeinTiny_0002.nii.gz --dataset raw/Dataset903_ArteryVeinTiny --case ArteryVeinTiny_0002 --out one.json --quiet", dir_);
  ASSERT_EQ(one.code, 0) << one.err;
  EXPECT_EQ(Json::parse(slurp(dir_ / "one.json"))["overlap"]["dice"], 1.0);
  const auto unknown = run("score pred/ArteryVeinTiny_0002.nii.gz --dataset raw/Dataset903_ArteryVeinTiny --case Nope_0002", dir_);
  EXPECT_EQ(unknown.code, 2);
  EXPECT_NE(unknown.err.find("has no case Nope_0002"), std::string::npos) << unknown.err;
}

}  // namespace

namespace {

// Betti numbers of shapes whose topology is known: a ball (1, 0, 0), two balls (2, 0, 0), a
// hollow ball (1, 0, 1), a solid torus (1, 1, 0), a ring of two tori linked by a bar (1, 2, 0),
// diagonal neighbours (26-connected: one piece), an empty volume (0, 0, 0).
// The registry is the one list: every metric has its definition in the results, its headline
// columns in the CSV header in registry order, and a row in the docs' table of metrics.
TEST(Score, EveryRegisteredMetricIsDefinedInTheResultsInTheCsvAndInTheDocs) {
  std::ifstream in(test::sourceDir() / "docs/scoring.md");
  const std::string section((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::string header = "case";
  for (const auto* m : scoreMetrics()) {
    EXPECT_EQ(findScoreMetric(m->key), m);
    EXPECT_NE(section.find(std::string("`") + m->key + "`"), std::string::npos) << m->key << " is missing from docs/scoring.md's table";
    EXPECT_GT(std::string(m->definition).size(), 40u) << m->key;
    for (const auto& h : m->headline) (header += ',') += h.column;
  }
  EXPECT_EQ(scoreCsvHeader(), header + "\n");
  CaseScores none;
  const auto defs = Json::parse(none.toJson().dump())["definitions"];
  for (const auto* m : scoreMetrics()) EXPECT_TRUE(defs.contains(m->key)) << m->key;
}

// Solid boxes as masks, their box Boundary IoU against the values the TopCoW 2024 evaluation's
// own tests state for the same boxes (size, location), and the box IoU at a ratio of one half.
TEST(Score, BoxBoundaryIoUHasTheTopCowEvaluationsValues) {
  const auto box = [](std::array<int, 3> size, std::array<int, 3> at) {
    Volume<std::uint8_t> v(grid(20, Vec3(0.5, 0.5, 2)));
    for (int k = at[2]; k < at[2] + size[2]; ++k)
      for (int j = at[1]; j < at[1] + size[1]; ++j)
        for (int i = at[0]; i < at[0] + size[0]; ++i) v.at(i, j, k) = 1;
    return v;
  };
  EXPECT_DOUBLE_EQ(*boxBoundaryIoU(box({6, 3, 3}, {0, 0, 0}), box({6, 3, 3}, {2, 1, 1}), 0.2), 12.0 / 92);
  EXPECT_DOUBLE_EQ(*boxBoundaryIoU(box({6, 3, 3}, {0, 0, 0}), box({6, 3, 3}, {3, 1, 1}), 0.2), 10.0 / 94);
  EXPECT_DOUBLE_EQ(*boxBoundaryIoU(box({6, 3, 3}, {0, 2, 0}), box({4, 7, 3}, {1, 0, 0}), 0.2), 30.0 / 100);
  EXPECT_DOUBLE_EQ(*boxBoundaryIoU(box({9, 6, 4}, {0, 0, 0}), box({3, 8, 4}, {3, 0, 0}), 0.2), 56.0 / 228);
  EXPECT_DOUBLE_EQ(*boxBoundaryIoU(box({9, 6, 4}, {0, 0, 0}), box({3, 8, 4}, {3, 0, 0}), 0.5), 0.3);
  EXPECT_DOUBLE_EQ(*boxBoundaryIoU(box({3, 4, 5}, {0, 0, 0}), box({5, 4, 3}, {1, 0, 0}), 0.5), 24.0 / 96);
  EXPECT_FALSE(boxBoundaryIoU(box({3, 4, 5}, {0, 0, 0}), Volume<std::uint8_t>(grid(20, Vec3(0.5, 0.5, 2))), 0.2));
}

// The inner band of a ball: its border voxels at one voxel's width, every voxel once the band is
// wider than the ball, and the two shifted balls' Boundary IoU below their IoU (the band weighs
// the boundary only).
TEST(Score, BoundaryBandsOfBallsAndTheirIoU) {
  const VolumeGrid g = grid(32, Vec3(0.25, 0.25, 0.25));
  const Volume<std::uint8_t> a = ball(g, Vec3(4, 4, 4), 2.5), b = ball(g, Vec3(4.5, 4, 4), 2.5);
  const auto count = [](const Volume<std::uint8_t>& v) { return std::count(v.data.begin(), v.data.end(), 1); };
  const auto thin = innerBoundaryBand(a, 0.25);
  EXPECT_EQ(count(thin), std::int64_t(border(a).size()));
  EXPECT_EQ(innerBoundaryBand(a, 10).data, a.data);
  const auto iou = [&](const Volume<std::uint8_t>& p, const Volume<std::uint8_t>& t) {
    std::int64_t both = 0, either = 0;
    for (std::size_t i = 0; i < p.data.size(); ++i) both += p.data[i] && t.data[i], either += p.data[i] || t.data[i];
    return double(both) / double(either);
  };
  const double whole = iou(a, b), boundary = iou(innerBoundaryBand(a, 0.5), innerBoundaryBand(b, 0.5));
  EXPECT_LT(boundary, whole - 0.2) << whole << " " << boundary;
  EXPECT_DOUBLE_EQ(iou(innerBoundaryBand(a, 10), innerBoundaryBand(b, 10)), whole);
}

TEST(Score, BettiNumbersOfShapesWithKnownTopology) {
  const VolumeGrid g = grid(40, Vec3(1, 1, 1));
  const auto make = [&](auto&& inside) {
    Volume<std::uint8_t> v(g);
    for (int k = 0; k < 40; ++k)
      for (int j = 0; j < 40; ++j)
        for (int i = 0; i < 40; ++i) v.at(i, j, k) = inside(Vec3(i, j, k));
    return v;
  };
  const auto torus = [](const Vec3& p, const Vec3& c, double R, double r) {
    const Vec3 d = p - c;
    const double q = std::sqrt(d.x * d.x + d.y * d.y) - R;
    return q * q + d.z * d.z <= r * r;
  };
  const auto expect = [](const Volume<std::uint8_t>& v, std::int64_t b0, std::int64_t b1, std::int64_t b2, const char* what) {
    const Betti b = bettiNumbers(v);
    EXPECT_EQ(b.b0, b0) << what;
    EXPECT_EQ(b.b1, b1) << what;
    EXPECT_EQ(b.b2, b2) << what;
  };
  const Vec3 c(20, 20, 20);
  expect(make([&](const Vec3& p) { return distance(p, c) <= 8; }), 1, 0, 0, "ball");
  expect(make([&](const Vec3& p) { return distance(p, Vec3(10, 10, 10)) <= 5 || distance(p, Vec3(28, 28, 28)) <= 6; }), 2, 0, 0, "two balls");
  expect(make([&](const Vec3& p) { return distance(p, c) <= 12 && distance(p, c) >= 8; }), 1, 0, 1, "hollow ball");
  expect(make([&](const Vec3& p) { return torus(p, c, 10, 3); }), 1, 1, 0, "torus");
  expect(make([&](const Vec3& p) {
           return torus(p, Vec3(12, 20, 20), 6, 2.5) || torus(p, Vec3(28, 20, 20), 6, 2.5) ||
                  (std::abs(p.y - 20) <= 1 && std::abs(p.z - 20) <= 1 && p.x >= 16 && p.x <= 24);
         }),
         1, 2, 0, "two tori joined by a bar");
  Volume<std::uint8_t> diagonal(g);
  diagonal.at(5, 5, 5) = diagonal.at(6, 6, 6) = diagonal.at(7, 7, 7) = 1;
  expect(diagonal, 1, 0, 0, "voxels touching at corners");
  expect(Volume<std::uint8_t>(g), 0, 0, 0, "empty");
}

}  // namespace

namespace {

// The skeleton is scikit-image's skeletonize_3d voxel for voxel (Debian's python3-skimage) on
// the masks of generated trees (3D CCO, VascuSynth's rods, a 2D disc) and on a thick shape, so
// clDice matches the public implementations.
TEST_F(ScoreRun, SkeletonIsScikitImagesVoxelForVoxel) {
  const std::map<std::string, std::string> params{
      {"cco3d", "seed = 2\n[domain]\nshape = \"sphere\"\nradius = \"6 mm\"\nvoxel_size = \"0.2 mm\"\n[tree]\nmethod = \"cco\"\nterminals = 300\n"},
      {"disc2d",
       "seed = 2\n[domain]\nshape = \"disc\"\nradius = \"20 mm\"\nvoxel_size = \"0.1 mm\"\n[tree]\nmethod = \"cco\"\nterminals = "
       "300\n[physics]\nperfusion_flow = \"2 mL/min\"\n"},
      {"vs", "seed = 3\n[domain]\ndemand_map = '" + (src_ / "demand_maps/vascusynth_rods_100.txt").string() +
                 "'\nsupply_coefficients = [0.65, 0.34, 0.01, 7]\nvoxel_size = \"0.4 mm\"\n[tree]\nterminals = 300\nroot_voxel = [0, 50, 50]\n"
                 "[physics]\nviscosity = \"3.6 mPa*s\"\nperfusion_pressure = \"13300 Pa\"\nterminal_pressure = \"8300 Pa\"\nperfusion_flow = \"8330 "
                 "mm3/s\"\n"}};
  for (const auto& [name, text] : params) {
    std::ofstream(dir_ / (name + ".toml")) << text << "[image]\nformats = [\"nifti\"]\n";
    ASSERT_EQ(run("generate " + name + ".toml --out " + name + " --quiet", dir_).code, 0) << name;
  }
  // A thick tube bent into an L (medial thinning of a solid, not only thin vessels).
  Volume<std::uint8_t> tube(grid(30, Vec3(1, 1, 1)));
  for (int k = 0; k < 30; ++k)
    for (int j = 0; j < 30; ++j)
      for (int i = 0; i < 30; ++i)
        tube.at(i, j, k) =
            (std::hypot(j - 8.3, k - 14.6) <= 4.5 && i >= 4 && i <= 24) || (std::hypot(i - 20.2, k - 14.6) <= 4.5 && j >= 8 && j <= 27);
  writeNifti(dir_ / "tube.nii.gz", viewOf(tube, true, "tube"));
  for (const std::string mask : {"cco3d/mask.nii.gz", "disc2d/mask.nii.gz", "vs/mask.nii.gz", "tube.nii.gz"}) {
    const NiftiVolume m = readNiftiVolume(dir_ / mask, 1ULL << 32, 4, "mask");
    Volume<std::uint8_t> b(m.values.grid);
    for (std::size_t i = 0; i < b.data.size(); ++i) b.data[i] = m.values.data[i] > 0;
    const Volume<std::uint8_t> s = skeletonize(b);
    writeNifti(dir_ / "ours.nii.gz", viewOf(s, true, "skeleton"));
    const std::string out = debianPython(R"(
import numpy as np, nibabel as nib
from skimage.morphology import skeletonize_3d
m = np.asarray(nib.load(')" + mask + R"(').dataobj) > 0
ref = skeletonize_3d(m.astype(np.uint8)) > 0
ours = np.asarray(nib.load('ours.nii.gz').dataobj) > 0
print('mask', int(m.sum()), 'skeleton', int(ref.sum()), 'different', int((ref != ours).sum()))
)",
                                         dir_);
    long mask_voxels = 0, skeleton = 0, different = -1;
    ASSERT_EQ(std::sscanf(out.c_str(), "mask %ld skeleton %ld different %ld", &mask_voxels, &skeleton, &different), 3) << out;
    EXPECT_EQ(different, 0) << mask << ": " << out;
    EXPECT_GT(skeleton, 10) << mask;
    EXPECT_LT(skeleton, mask_voxels) << mask;  // not vacuous: thinning removed voxels
  }
}

}  // namespace

namespace {

// The calibre plot puts each curve's points where its recall says, in its colour, and leaves a
// bin without voxels empty.
TEST(Score, CalibrePlotDrawsEachCurveAtItsRecall) {
  // Bins as the program writes them: doubling in width, the last open.
  CalibreCurve a{{0, 0.5, 1, 2}, {0.0, 0.5, 1.0, NAN}, {0.5, 1, 2, INFINITY}, "threshold_150"};
  CalibreCurve b{{0, 0.5, 1, 2}, {1.0, 1.0, 1.0, 1.0}, {0.5, 1, 2, INFINITY}, ""};
  const Image8 img = plotCalibreCurves({a, b});
  const CalibrePlotFrame f = calibrePlotFrame({a, b});
  ASSERT_EQ(img.channels, 3);
  ASSERT_EQ(img.width, f.width);
  const auto rgb = [&](int x, int y) {
    const auto* p = &img.pixels[(std::size_t(y) * img.width + x) * 3];
    return (std::uint32_t(p[0]) << 16) | (std::uint32_t(p[1]) << 8) | p[2];
  };
  // Each bin a step across its true extent on the square-root axis: [0.5, 1) at recall 0.5 from
  // just after 0.5 to just before 1 voxel; the open bin drawn to twice its lower edge.
  EXPECT_EQ(f.x_max, 4.0);
  EXPECT_EQ(rgb(f.x(0.55), f.y(0.5)), 0xD62728u);
  EXPECT_EQ(rgb(f.x(0.95), f.y(0.5)), 0xD62728u);
  EXPECT_EQ(rgb(f.x(0.25), f.y(0.0) - 2), 0xD62728u);
  EXPECT_EQ(rgb(f.x(3.5), f.y(1.0)), 0x1F77B4u);  // curve 2 (drawn last) at recall 1 in the open bin
  EXPECT_EQ(rgb(f.x(3.0), f.y(0.6)), 0xFFFFFFu);  // curve 1 has no step in its empty bin (0.6: off the grid lines)
  // The axis is not one of equal bins: [0, 0.5) takes as much width as sqrt(0.5) of the axis's sqrt(4).
  EXPECT_NEAR(f.x(0.5) - f.left, f.plot_width * std::sqrt(0.5 / 4), 1);
  // The legend names the curves: a longer name widens the picture by its characters.
  CalibreCurve longer = a;
  longer.name = "threshold_150_longer";
  EXPECT_EQ(calibrePlotFrame({longer, b}).width - f.width, 12 * 7);
}

}  // namespace

namespace {

// Per class: an artery-vein forest scored with its own classes as the prediction (each class
// perfect), with the labels swapped (each class 0), and as a binary prediction (recall only).
TEST_F(ScoreRun, PerClassScoresTellArteryFromVein) {
  std::ofstream(dir_ / "av.toml") << "seed = 5\n[domain]\nshape = \"sphere\"\nradius = \"8 mm\"\nvoxel_size = \"0.25 mm\"\n"
                                     "[tree]\nmethod = \"cco\"\nterminals = 80\n"
                                     "[[tree.inlet]]\nkind = \"artery\"\nroot_offset = [-1.5, 7.8, 0]\n"
                                     "[[tree.inlet]]\nkind = \"vein\"\nroot_offset = [1.5, 7.8, 0]\n"
                                     "[physics]\nperfusion_pressure = \"100 mmHg\"\nterminal_pressure = \"60 mmHg\"\nperfusion_flow = \"20 mL/min\"\n"
                                     "[image]\nformats = [\"nifti\"]\n";
  ASSERT_EQ(run("generate av.toml --out s --quiet", dir_).code, 0);
  const NiftiVolume cls = readNiftiVolume(dir_ / "s/classes.nii.gz", 1ULL << 32, 4, "classes");
  Volume<std::uint8_t> same(cls.values.grid), swapped(cls.values.grid), binary(cls.values.grid);
  for (std::size_t i = 0; i < same.data.size(); ++i) {
    const auto c = std::uint8_t(std::lround(cls.values.data[i]));
    same.data[i] = c;
    swapped.data[i] = c == 1 ? 2 : c == 2 ? 1 : 0;
    binary.data[i] = c > 0;
  }
  writeNifti(dir_ / "same.nii.gz", viewOf(same, true, "kinds"));
  writeNifti(dir_ / "swapped.nii.gz", viewOf(swapped, true, "kinds swapped"));
  writeNifti(dir_ / "binary.nii.gz", viewOf(binary, true, "binary"));
  for (const std::string p : {"same", "swapped", "binary"}) {
    ASSERT_EQ(run("score " + p + ".nii.gz s --out " + p + ".json --quiet", dir_).code, 0) << p;
    const Json j = Json::parse(slurp(dir_ / (p + ".json")));
    ASSERT_TRUE(j.contains("per_class")) << p;
    for (const char* kind : {"artery", "vein"}) {
      const Json& c = j["per_class"]["classes"][kind];
      const double want = p == "swapped" ? 0.0 : 1.0;
      EXPECT_EQ(c["overlap"]["recall"].get<double>(), want) << p << " " << kind;
      EXPECT_EQ(c["centreline"]["recall"].get<double>(), want) << p << " " << kind;
      EXPECT_EQ(c["overlap"].contains("dice"), p != "binary") << p << " " << kind;
      EXPECT_GT(c["centreline"]["voxels"].get<int>(), 50) << kind;
    }
  }
}

}  // namespace

namespace {

// Per-class scores of a generated artery-vein sample against SciPy and scikit-image, computed
// as the TopCoW 2024 evaluation computes them: the prediction the truth's classes shifted by a
// voxel, a block of artery relabelled as vein; classes the union of both volumes' values; Dice
// by counting; b0 by skimage.measure.label (26-connected); HD95 from 26-neighbour contours and
// SciPy's distance transform (the larger directed 95th percentile); clDice by skeletonize_3d.
TEST_F(ScoreRun, PerClassScoresAgreeWithScipyAndScikitImageAsTopCowComputesThem) {
  std::ofstream(dir_ / "av.toml") << "seed = 7\n[domain]\nshape = \"sphere\"\nradius = \"6 mm\"\nvoxel_size = \"0.25 mm\"\n"
                                     "[tree]\nmethod = \"cco\"\nterminals = 60\n"
                                     "[[tree.inlet]]\nkind = \"artery\"\nroot_offset = [-1.5, 5.8, 0]\n"
                                     "[[tree.inlet]]\nkind = \"vein\"\nroot_offset = [1.5, 5.8, 0]\n"
                                     "[physics]\nperfusion_pressure = \"100 mmHg\"\nterminal_pressure = \"60 mmHg\"\nperfusion_flow = \"20 mL/min\"\n"
                                     "[image]\nformats = [\"nifti\"]\nvoxel_size = \"0.3 mm\"\n";
  ASSERT_EQ(run("generate av.toml --out s --quiet", dir_).code, 0);
  const std::string out = debianPython(R"(
import nibabel as nib, numpy as np
img = nib.load('s/classes.nii.gz')
t = np.asarray(img.dataobj).astype(np.uint8)
p = np.zeros_like(t)
p[1:] = t[:-1]
n = t.shape[0]
block = p[n // 3:n // 2]
block[block == 1] = 2
nib.save(nib.Nifti1Image(p, img.affine, img.header), 'shifted.nii.gz')
)",
                                       dir_);
  ASSERT_EQ(run("score shifted.nii.gz s --topcow --out t.json --quiet", dir_).code, 0);
  const std::string check = debianPython(R"(
import json
import nibabel as nib, numpy as np
from scipy import ndimage
from skimage import measure
from skimage.morphology import skeletonize_3d
img = nib.load('s/classes.nii.gz')
h = img.header.get_zooms()[:3]
t = np.asarray(img.dataobj).astype(np.uint8)
p = np.asarray(nib.load('shifted.nii.gz').dataobj).astype(np.uint8)
ours = json.load(open('t.json'))['per_class']
legend = json.load(open('s/sample.json'))['classes']
def contour(a):
    a = np.pad(a, 1)
    return (a & ~ndimage.binary_erosion(a, structure=np.ones((3, 3, 3)), border_value=0))[1:-1, 1:-1, 1:-1]
def hd95(a, b):
    ca, cb = contour(a), contour(b)
    da = ndimage.distance_transform_edt(~cb, sampling=h)[ca]
    db = ndimage.distance_transform_edt(~ca, sampling=h)[cb]
    return max(np.percentile(da, 95), np.percentile(db, 95))
def cl(a, b):
    sa, sb = skeletonize_3d(a) > 0, skeletonize_3d(b) > 0
    tprec = (sa & b).sum() / sa.sum() if sa.sum() else 0.0
    tsens = (sb & a).sum() / sb.sum() if sb.sum() else 0.0
    return 0.0 if tprec + tsens == 0 else 2 * tprec * tsens / (tprec + tsens)
worst, rows = 0.0, []
for v in sorted(set(np.unique(t)) | set(np.unique(p)) - {0}):
    if v == 0: continue
    a, b = p == v, t == v
    ref = {'dice': 2 * (a & b).sum() / (a.sum() + b.sum()),
           'b0_error': abs(measure.label(a, connectivity=3).max() - measure.label(b, connectivity=3).max()),
           'hd95_mm': hd95(a, b), 'cldice': cl(a, b)}
    k = ours['classes'][legend[str(v)]]
    got = {'dice': k['overlap']['dice'], 'b0_error': k['b0']['error'], 'hd95_mm': k['surface']['hd95_mm'], 'cldice': k['cldice']['cldice']}
    worst = max(worst, max(abs(ref[x] - got[x]) for x in ref))
    rows.append(ref)
for x in ('dice', 'b0_error', 'hd95_mm', 'cldice'):
    worst = max(worst, abs(np.mean([r[x] for r in rows]) - ours['class_average'][x]))
print('classes', len(rows), 'max_difference', worst, 'b0_error', rows[0]['b0_error'] + rows[1]['b0_error'], 'dice', rows[0]['dice'])
)",
                                         dir_);
  int classes = 0, b0 = 0;
  double diff = 1, dice = 1;
  ASSERT_EQ(std::sscanf(check.c_str(), "classes %d max_difference %lf b0_error %d dice %lf", &classes, &diff, &b0, &dice), 4) << out << check;
  EXPECT_EQ(classes, 2);
  EXPECT_LT(diff, 1e-9) << check;
  EXPECT_GT(b0, 0) << check;  // not vacuous: the relabelled block splits a class
  EXPECT_LT(dice, 0.9) << check;
}

// A tube (radius 3 voxels along x) and the same tube with a 4-voxel gap: exact overlap counts,
// two pieces instead of one (b0 error 1), the prediction's skeleton wholly in the truth (topology
// precision 1) while the truth's skeleton crosses the gap (sensitivity below 1).
TEST(Score, TubeWithAGapLosesItsGapAndItsConnectivity) {
  const VolumeGrid g = grid(40, Vec3(1, 1, 1));
  Volume<std::uint8_t> truth(g), pred(g);
  std::int64_t tube = 0, gap = 0;
  for (int k = 0; k < 40; ++k)
    for (int j = 0; j < 40; ++j)
      for (int i = 5; i <= 34; ++i) {
        if (std::hypot(j - 19.0, k - 19.0) > 3) continue;
        truth.at(i, j, k) = 1, ++tube;
        const bool in_gap = i >= 18 && i <= 21;
        pred.at(i, j, k) = !in_gap, gap += in_gap;
      }
  const Json o = Json::parse(overlapScores(pred, truth, false).dump());
  EXPECT_EQ(o["false_negative_voxels"].get<std::int64_t>(), gap);
  EXPECT_EQ(o["false_positive_voxels"].get<std::int64_t>(), 0);
  EXPECT_DOUBLE_EQ(o["recall"].get<double>(), double(tube - gap) / double(tube));
  EXPECT_DOUBLE_EQ(o["dice"].get<double>(), 2.0 * (tube - gap) / (2.0 * (tube - gap) + gap));
  const Betti bt = bettiNumbers(truth), bp = bettiNumbers(pred);
  EXPECT_EQ(bt.b0, 1);
  EXPECT_EQ(bp.b0, 2);
  EXPECT_EQ(bp.b1 + bt.b1 + bp.b2 + bt.b2, 0);
  const Json c = Json::parse(clDice(skeletonize(pred), truth, skeletonize(truth), pred, false).dump());
  ASSERT_TRUE(c["topology_precision"].is_number() && c["topology_sensitivity"].is_number()) << c.dump();
  EXPECT_EQ(c["topology_precision"].get<double>(), 1.0);
  EXPECT_LT(c["topology_sensitivity"].get<double>(), 0.95);
  EXPECT_GT(c["topology_sensitivity"].get<double>(), 0.7);
  // Lee's thinning (scikit-image's alike) erases a straight tube whose cross-section is 6 voxels
  // across, centred on a voxel corner: the published clDice is blind there; the exact centreline
  // variant is not.
  Volume<std::uint8_t> even(g);
  for (int k = 0; k < 40; ++k)
    for (int j = 0; j < 40; ++j)
      for (int i = 5; i <= 34; ++i) even.at(i, j, k) = std::hypot(j - 19.5, k - 19.5) <= 3;
  const auto s = skeletonize(even);
  EXPECT_EQ(std::count(s.data.begin(), s.data.end(), 1), 0);
}

}  // namespace

namespace {

// Labelled volumes written as NIfTI for `score PRED TRUTH`: bars one voxel thick along x.
struct Phantom {
  Volume<std::uint8_t> v;
  explicit Phantom(int n, const Vec3& origin = Vec3(0, 0, 0))
      : v([&] {
          VolumeGrid g;
          g.dims = {n, n, n};
          g.origin_mm = origin;
          return g;
        }()) {}
  Phantom& bar(int value, int x0, int x1, int y, int z) {
    for (int x = x0; x <= x1; ++x) v.at(x, y, z) = std::uint8_t(value);
    return *this;
  }
  Phantom& column(int value, int x, int y0, int y1, int z) {
    for (int y = y0; y <= y1; ++y) v.at(x, y, z) = std::uint8_t(value);
    return *this;
  }
  void write(const fs::path& f) const { writeNifti(f, viewOf(v, true, "phantom")); }
};

// A plain pair of labelled NIfTI volumes, every number derived by hand: class 1 a bar of 10
// voxels predicted as its first 8; class 2 the same predicted in two pieces of 4 (a 2-voxel
// gap); class 3 in the legend and in neither volume; class 4 one voxel of the truth only; class
// 5 one voxel of the prediction only (4 and 5 not in the legend).
TEST_F(ScoreRun, PlainLabelledPairScoresEveryClassAsDerivedByHand) {
  Phantom truth(20), pred(20);
  truth.bar(1, 2, 11, 5, 5).bar(2, 2, 11, 12, 12).bar(4, 15, 15, 15, 15);
  pred.bar(1, 2, 9, 5, 5).bar(2, 2, 5, 12, 12).bar(2, 8, 11, 12, 12).bar(5, 17, 17, 3, 3);
  truth.write(dir_ / "truth.nii.gz");
  pred.write(dir_ / "pred.nii.gz");
  const auto r = run("score pred.nii.gz truth.nii.gz --legend 1=first,2=second,3=third --out d.json", dir_);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("warning: label 4 occurs in the truth but not in the legend"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("warning: label 5 occurs in the prediction but not in the legend"), std::string::npos) << r.err;
  const Json d = Json::parse(slurp(dir_ / "d.json"));
  EXPECT_NE(d["truth_is"].get<std::string>().find("annotation truth.nii.gz"), std::string::npos);
  EXPECT_FALSE(d.contains("centreline"));  // no centreline given: no centreline metrics
  EXPECT_FALSE(d.contains("calibre"));
  EXPECT_DOUBLE_EQ(d["overlap"]["dice"].get<double>(), 32.0 / 38.0);  // the classes merged: 21 and 17 voxels, 16 common
  const Json& k = d["per_class"]["classes"];
  EXPECT_DOUBLE_EQ(k["first"]["overlap"]["dice"].get<double>(), 16.0 / 18.0);
  EXPECT_DOUBLE_EQ(k["first"]["cldice"]["cldice"].get<double>(), 2 * 0.8 / 1.8);  // Tprec 1, Tsens 8/10
  EXPECT_NEAR(k["first"]["surface"]["hd95_mm"].get<double>(), 1.55, 1e-12);       // truth to prediction 0 ×8, 1, 2
  EXPECT_DOUBLE_EQ(k["first"]["surface"]["hd_mm"].get<double>(), 2.0);
  EXPECT_EQ(k["first"]["b0"]["error"], 0);
  EXPECT_DOUBLE_EQ(k["second"]["overlap"]["dice"].get<double>(), 16.0 / 18.0);
  EXPECT_EQ(k["second"]["b0"], Json({{"truth", 1}, {"prediction", 2}, {"error", 1}}));
  EXPECT_DOUBLE_EQ(k["second"]["surface"]["hd95_mm"].get<double>(), 1.0);
  EXPECT_EQ(k["third"]["absent"], true);
  EXPECT_EQ(k["label 4"]["overlap"]["dice"], 0.0);
  EXPECT_TRUE(k["label 4"]["surface"]["hd95_mm"].is_null());
  EXPECT_TRUE(k["label 4"]["cldice"]["cldice"].is_null());
  EXPECT_EQ(k["label 5"]["overlap"]["dice"], 0.0);
  EXPECT_EQ(k["label 5"]["b0"]["error"], 1);
  const Json& avg = d["per_class"]["class_average"];
  EXPECT_EQ(avg["classes"], 4);  // present in either volume: 1, 2, 4, 5
  EXPECT_DOUBLE_EQ(avg["dice"].get<double>(), (16.0 / 18.0) * 2 / 4);
  EXPECT_DOUBLE_EQ(avg["b0_error"].get<double>(), 0.75);
  EXPECT_NEAR(avg["hd95_mm"].get<double>(), (1.55 + 1.0) / 2, 1e-12);  // defined for 2 classes only
  EXPECT_EQ(avg["hd95_mm_classes"], 2);
  // TopCoW: a class on one side only scores HD95 90 mm and clDice 0, and is averaged.
  ASSERT_EQ(run("score pred.nii.gz truth.nii.gz --legend 1=first,2=second,3=third --topcow --out t.json --quiet", dir_).code, 0);
  const Json t = Json::parse(slurp(dir_ / "t.json"));
  const Json& ta = t["per_class"]["class_average"];
  EXPECT_NEAR(ta["hd95_mm"].get<double>(), (1.55 + 1.0 + 90 + 90) / 4, 1e-12);
  EXPECT_DOUBLE_EQ(ta["cldice"].get<double>(), (2 * 0.8 / 1.8) * 2 / 4);
  EXPECT_EQ(t["per_class"]["classes"]["label 4"]["cldice"]["cldice"], 0.0);
  EXPECT_EQ(t["per_class"]["classes"]["label 4"]["surface"]["hd95_mm"], 90.0);
  // The CSV carries the class averages.
  ASSERT_EQ(run("score pred.nii.gz truth.nii.gz --csv d.csv --quiet", dir_).code, 0);
  const std::string csv = slurp(dir_ / "d.csv");
  EXPECT_NE(csv.find("class_avg_dice"), std::string::npos) << csv;
}

// TopCoW's conventions in every empty case (its evaluation, topcow24_eval): both masks empty,
// the prediction empty, the truth empty; binary and with the scheme's classes.
TEST_F(ScoreRun, TopCowConventionsHoldInEveryEmptyCase) {
  Phantom some(16), none(16);
  some.bar(1, 2, 12, 8, 8);
  some.write(dir_ / "some.nii.gz");
  none.write(dir_ / "none.nii.gz");
  struct Case {
    const char *pred, *truth;
    double hd95;  // TopCoW's
  };
  for (const Case& c : {Case{"none", "none", 0.0}, Case{"none", "some", 90.0}, Case{"some", "none", 90.0}}) {
    const std::string what = std::string(c.pred) + " against " + c.truth;
    ASSERT_EQ(
        run(std::string("score ") + c.pred + ".nii.gz " + c.truth + ".nii.gz --topcow --label-scheme topcow2024 --out t.json --force --quiet", dir_)
            .code,
        0)
        << what;
    const Json t = Json::parse(slurp(dir_ / "t.json"));
    EXPECT_EQ(t["overlap"]["dice"], 0.0) << what;
    EXPECT_EQ(t["cldice"]["skeletons"]["cldice"], 0.0) << what;
    EXPECT_EQ(t["surface"]["hd95_mm"], c.hd95) << what;
    EXPECT_EQ(t["boundary_iou"]["boundary_iou"], 0.0) << what;
    EXPECT_EQ(t["boundary_iou"]["bounding_box"]["iou"], 0.0) << what;
    const Json& avg = t["per_class"]["class_average"];
    EXPECT_EQ(avg["dice"], 0.0) << what;  // no class at all: every class average 0
    if (std::string(c.pred) == "none" && std::string(c.truth) == "none") {
      EXPECT_EQ(avg["classes"], 0);
      EXPECT_EQ(avg["hd95_mm"], 0.0);
      EXPECT_EQ(avg["b0_error"], 0.0);
    } else {
      EXPECT_EQ(avg["classes"], 1) << what;  // BA on one side only
      EXPECT_EQ(avg["hd95_mm"], 90.0) << what;
      EXPECT_EQ(avg["b0_error"], 1.0) << what;
      EXPECT_EQ(t["per_class"]["classes"]["BA"]["cldice"]["cldice"], 0.0) << what;
    }
    ASSERT_EQ(run(std::string("score ") + c.pred + ".nii.gz " + c.truth + ".nii.gz --out d.json --force --quiet", dir_).code, 0) << what;
    const Json d = Json::parse(slurp(dir_ / "d.json"));
    EXPECT_EQ(d["overlap"]["dice"], std::string(c.pred) == std::string(c.truth) ? 1.0 : 0.0) << what;
    EXPECT_TRUE(d["cldice"]["skeletons"]["cldice"].is_null()) << what;
  }
}

// The Circle of Willis drawn as touching bars (patient left at smaller world x): BA, both PCAs,
// the right Pcom, both ICAs, both ACAs and the Acom. Anterior variant (L-A1, Acom, 3rd-A2, R-A1)
// 1 1 0 1, posterior (L-Pcom, L-P1, R-P1, R-Pcom) 0 1 1 1. The prediction misses the Acom.
TEST_F(ScoreRun, TopCowSchemeClassifiesVariantsAndMatchesTopology) {
  Phantom truth(30);
  truth.column(1, 15, 5, 10, 10).bar(3, 8, 14, 10, 10).bar(2, 16, 22, 11, 10).column(8, 22, 12, 16, 10);
  truth.column(4, 22, 17, 20, 10).column(6, 8, 17, 20, 10).bar(12, 8, 13, 21, 10).bar(11, 17, 22, 21, 10).bar(10, 14, 16, 21, 10);
  Phantom pred = truth;
  for (auto& v : pred.v.data)
    if (v == 10) v = 0;
  truth.write(dir_ / "truth.nii.gz");
  pred.write(dir_ / "pred.nii.gz");
  ASSERT_EQ(run("score pred.nii.gz truth.nii.gz --label-scheme topcow2024 --topcow --out t.json --quiet", dir_).code, 0);
  const Json t = Json::parse(slurp(dir_ / "t.json"));
  const Json& cow = t["label_scheme"]["circle_of_willis"];
  EXPECT_EQ(cow["truth"]["anterior"], "Var_Ant_1_1_0_1");
  EXPECT_EQ(cow["truth"]["posterior"], "Var_Pos_0_1_1_1");
  EXPECT_EQ(cow["prediction"]["anterior"], "Var_Ant_1_0_0_1");
  EXPECT_EQ(cow["variant_match"], Json({{"anterior", false}, {"posterior", true}}));
  EXPECT_EQ(cow["topology"]["anterior"]["match"], false);
  EXPECT_EQ(cow["topology"]["anterior"]["why_not"], "Acom detection FN");
  EXPECT_EQ(cow["topology"]["posterior"]["match"], true) << cow["topology"]["posterior"];
  EXPECT_EQ(cow["topology"]["posterior"]["left_right_flipped"], false);
  EXPECT_EQ(cow["topology"]["anterior"]["labels"]["L-ACA"]["neighbours_truth"], Json::array({6, 10}));
  const Json& det = t["label_scheme"]["detection"]["labels"];
  EXPECT_EQ(det["R-Pcom"]["detection"], "TP");
  EXPECT_EQ(det["L-Pcom"]["detection"], "TN");
  EXPECT_EQ(det["Acom"]["detection"], "FN");
  EXPECT_EQ(det["3rd-A2"]["detection"], "TN");
  EXPECT_EQ(t["per_class"]["classes"]["Acom"]["overlap"]["dice"], 0.0);
  EXPECT_EQ(t["per_class"]["class_average"]["classes"], 9);
  // Over cases: detection F1 per vessel from the counts (undefined as 0, as TopCoW averages);
  // balanced accuracies over the true variants.
  const ScoreMetric* m = findScoreMetric("label_scheme");
  ASSERT_NE(m, nullptr);
  ASSERT_NE(m->aggregate, nullptr);
  const nlohmann::ordered_json one = nlohmann::ordered_json::parse(t["label_scheme"].dump());
  nlohmann::ordered_json right = one;
  right["circle_of_willis"]["prediction"]["anterior"] = "Var_Ant_1_1_0_1";
  right["circle_of_willis"]["topology"]["anterior"]["match"] = true;
  right["detection"]["labels"]["Acom"]["detection"] = "TP";
  nlohmann::ordered_json other = right;  // a third case of another anterior variant, classified right
  other["circle_of_willis"]["truth"]["anterior"] = "Var_Ant_1_0_0_1";
  other["circle_of_willis"]["prediction"]["anterior"] = "Var_Ant_1_0_0_1";
  const auto agg = m->aggregate({&one, &right, &other});
  EXPECT_DOUBLE_EQ(agg["detection"]["labels"]["Acom"]["f1"].get<double>(), 2.0 * 2 / (2 * 2 + 0 + 1));  // TP 2, FN 1
  EXPECT_EQ(agg["detection"]["labels"]["L-Pcom"]["f1"], 0.0);                                           // TN only
  EXPECT_DOUBLE_EQ(agg["detection"]["f1"]["mean"].get<double>(), (1.0 + 0.0 + 0.8 + 0.0) / 4);
  // Variant 1 1 0 1: one of two right; variant 1 0 0 1: one of one.
  EXPECT_DOUBLE_EQ(agg["circle_of_willis"]["variant_balanced_accuracy"]["anterior"].get<double>(), (0.5 + 1.0) / 2);
  EXPECT_DOUBLE_EQ(agg["circle_of_willis"]["topology_match_rate"]["anterior"].get<double>(), (0.5 + 1.0) / 2);
  EXPECT_DOUBLE_EQ(agg["circle_of_willis"]["topology_match_rate"]["posterior"].get<double>(), 1.0);
}

// TopBrain's invalid neighbours: the basilar artery touching the right M1, a pair its anatomy
// does not allow, is an error for both; the right M1 touching the right ICA is allowed.
TEST_F(ScoreRun, TopBrainSchemeCountsInvalidNeighbours) {
  Phantom truth(16), pred(16);
  truth.bar(1, 2, 6, 8, 8).bar(5, 9, 12, 8, 8).bar(4, 13, 14, 8, 8);
  pred.bar(1, 2, 7, 8, 8).bar(5, 8, 12, 8, 8).bar(4, 13, 14, 8, 8);
  truth.write(dir_ / "truth.nii.gz");
  pred.write(dir_ / "pred.nii.gz");
  ASSERT_EQ(run("score pred.nii.gz truth.nii.gz --label-scheme topbrain2025-ct --topcow --out t.json --quiet", dir_).code, 0);
  const Json t = Json::parse(slurp(dir_ / "t.json"));
  const Json& nb = t["label_scheme"]["invalid_neighbours"];
  EXPECT_EQ(nb["labels"]["BA"]["invalid"], Json::array({"R-M1"}));
  EXPECT_EQ(nb["labels"]["R-M1"]["invalid"], Json::array({"BA"}));
  EXPECT_EQ(nb["labels"]["R-ICA"]["error"], 0);
  EXPECT_DOUBLE_EQ(nb["class_average"].get<double>(), 2.0 / 3);
  EXPECT_EQ(t["label_scheme"]["detection"]["vessels"], "side road");
}

// Grids: a prediction whose header places the voxels 0.005 voxel away (float rounding) is
// accepted; 0.05 voxel is refused, naming the distance and the option that allows it.
TEST_F(ScoreRun, GridToleranceAcceptsHeaderRoundingAndRefusesAShift) {
  Phantom truth(12), near(12, Vec3(0.005, 0, 0)), far(12, Vec3(0.05, 0, 0));
  for (auto* p : {&truth, &near, &far}) p->bar(1, 2, 9, 6, 6);
  truth.write(dir_ / "truth.nii.gz");
  near.write(dir_ / "near.nii.gz");
  far.write(dir_ / "far.nii.gz");
  EXPECT_EQ(run("score near.nii.gz truth.nii.gz --out near.json --quiet", dir_).code, 0);
  const auto bad = run("score far.nii.gz truth.nii.gz --out far.json", dir_);
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.err.find("a corner voxel lies 0.05 mm (0.05 voxels) away; allowed: within 0.01 voxels (--grid-tolerance)"), std::string::npos)
      << bad.err;
  EXPECT_FALSE(fs::exists(dir_ / "far.json"));
  EXPECT_EQ(run("score far.nii.gz truth.nii.gz --grid-tolerance 0.1 --out far.json --quiet", dir_).code, 0);
}

// The truth a network learned from: a dataset made with the visible-vessel label policy (the
// default of a dataset with a degraded image), its labels as the prediction. Against the training
// label Dice 1; against the exact mask less, with both truths named in the results. Under the
// ignore policy the ignore label's voxels count neither way: labelsTr's every voxel > 0 as the
// prediction still scores Dice 1.
TEST_F(ScoreRun, VisibleVesselLabelScoresOneAgainstItselfAndLessAgainstTheExactMask) {
  const auto spec = [&](const std::string& name, int id, const std::string& image) {
    std::ofstream(dir_ / (name + ".toml"))
        << "[dataset]\nname = \"" << name << "\"\nid = " << id << "\nsamples = 1\nseed = 3\nprofile = \"cta\"\n"
        << "[domain]\ndemand_map = \"" << (src_ / "demand_maps/uniform_100.txt").string()
        << "\"\nvoxel_size = \"0.4 mm\"\n[tree]\nterminals = 150\nroot_voxel = [0, 50, 50]\n"
           "[physics]\nviscosity = \"3.6 mPa*s\"\nperfusion_pressure = \"13300 Pa\"\nterminal_pressure = \"8300 Pa\"\n"
           "perfusion_flow = \"8330 mm3/s\"\n[image]\nvoxel_size = \"0.625 mm\"\nsupersampling = 2\n"
        << image;
    EXPECT_EQ(run("dataset " + name + ".toml --out raw --quiet", dir_).code, 0) << name;
    const fs::path ds = dir_ / "raw" / ("Dataset" + std::to_string(id) + "_" + name);
    fs::create_directories(dir_ / ("pred_" + name));
    fs::copy_file(ds / "labelsTr" / (name + "_0000.nii.gz"), dir_ / ("pred_" + name) / (name + "_0000.nii.gz"));
    return ds;
  };
  const fs::path ds = spec("Visible", 904, "");
  EXPECT_EQ(Json::parse(slurp(ds / "dataset.json"))["label_policy"], "visible");
  ASSERT_EQ(run("score --dataset raw/Dataset904_Visible --predictions pred_Visible --out training.json --quiet", dir_).code, 0);
  ASSERT_EQ(run("score --dataset raw/Dataset904_Visible --predictions pred_Visible --truth exact --out exact.json --quiet", dir_).code, 0);
  const Json training = Json::parse(slurp(dir_ / "training.json")), exact = Json::parse(slurp(dir_ / "exact.json"));
  EXPECT_EQ(training["summary"]["dice"]["mean"], 1.0);
  EXPECT_NE(training["truth_is"].get<std::string>().find("label policy visible"), std::string::npos) << training["truth_is"];
  EXPECT_LT(exact["summary"]["dice"]["mean"].get<double>(), 0.95);
  EXPECT_LT(exact["summary"]["recall"]["mean"].get<double>(), 0.9);
  EXPECT_EQ(exact["summary"]["precision"]["mean"], 1.0);  // the visible label lies within the mask
  EXPECT_NE(exact["truth_is"].get<std::string>().find("exact mask"), std::string::npos) << exact["truth_is"];

  spec("Ignore", 905, "label_policy = \"ignore\"\n");
  ASSERT_EQ(run("score --dataset raw/Dataset905_Ignore --predictions pred_Ignore --out ignore.json --quiet", dir_).code, 0);
  const Json ignore = Json::parse(slurp(dir_ / "ignore.json"));
  EXPECT_NE(ignore["truth_is"].get<std::string>().find("ignore label (2) counts neither way"), std::string::npos) << ignore["truth_is"];
  EXPECT_EQ(ignore["summary"]["dice"]["mean"], 1.0);  // the predicted ignore voxels are not false positives
  const NiftiVolume label = readNiftiVolume(dir_ / "pred_Ignore/Ignore_0000.nii.gz", 1ULL << 32, 4, "label");
  EXPECT_GT(std::count(label.values.data.begin(), label.values.data.end(), 2.0f), 100);  // there were ignore voxels to count
}

}  // namespace
