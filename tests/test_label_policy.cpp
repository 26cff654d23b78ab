// Label policies: each policy's rule voxel by voxel on hand-made volumes, the length
// kept by calibre, the visible policy against an independent derivation on a grown tree (nibabel),
// and datasets whose labelsTr follow the policy (nnU-Net's ignore label declared).
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fstream>

#include "cli_run.hpp"
#include "core/vascular_tree.hpp"
#include "raster/ground_truth.hpp"
#include "raster/label_policy.hpp"

namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;
using namespace angiosynth;

// Five voxels in a row: partial volumes 0, 0.1 (crossed by a centreline), 0.3, 0.6, 1.
GroundTruthVolumes row() {
  VolumeGrid g;
  g.dims = {5, 1, 1};
  g.origin_mm = Vec3(0, 0, 0);
  GroundTruthVolumes gt;
  gt.fraction = Volume<float>(g);
  gt.mask = Volume<std::uint8_t>(g);
  gt.centerline = Volume<std::uint8_t>(g);
  const float pv[5] = {0, 0.1f, 0.3f, 0.6f, 1};
  const std::uint8_t mask[5] = {0, 1, 0, 1, 1}, centre[5] = {0, 1, 0, 0, 1};
  for (int i = 0; i < 5; ++i) gt.fraction.data[i] = pv[i], gt.mask.data[i] = mask[i], gt.centerline.data[i] = centre[i];
  return gt;
}

std::vector<int> values(const Label& l) { return std::vector<int>(l.values.data.begin(), l.values.data.end()); }

TEST(LabelPolicy, EachPolicyFollowsItsRuleVoxelByVoxel) {
  const GroundTruthVolumes gt = row();
  const LabelNumbering plain;
  LabelPolicy p;
  EXPECT_EQ(values(makeLabel(p, gt, plain)), (std::vector<int>{0, 1, 0, 1, 1}));  // binary: the mask
  p.name = "threshold";
  EXPECT_EQ(values(makeLabel(p, gt, plain)), (std::vector<int>{0, 0, 0, 1, 1}));
  p.threshold = 0.25;
  EXPECT_EQ(values(makeLabel(p, gt, plain)), (std::vector<int>{0, 0, 1, 1, 1}));
  p.name = "ignore";  // band (0.25, 0.75): the thin centreline voxel, 0.3 and 0.6 are ignored
  EXPECT_EQ(values(makeLabel(p, gt, plain)), (std::vector<int>{0, 2, 2, 2, 1}));
  p.ignore_band = {0.5, 0.55};
  EXPECT_EQ(values(makeLabel(p, gt, plain)), (std::vector<int>{0, 2, 0, 1, 1}));
  p.name = "soft";
  const Label soft = makeLabel(p, gt, plain);
  EXPECT_EQ(std::vector<float>(soft.soft.data.begin(), soft.soft.data.end()), (std::vector<float>{0, 0.1f, 0.3f, 0.6f, 1}));
  // Visible: mask voxels whose contrast reaches 2σ (σ = 2: contrast ≥ 4).
  p.name = "visible";
  Volume<float> contrast(gt.fraction.grid);
  const float c[5] = {9, 0.5f, 30, 5, 3.99f};
  for (int i = 0; i < 5; ++i) contrast.data[i] = c[i];
  const VisibilityEvidence ev{&contrast, 2};
  EXPECT_EQ(values(makeLabel(p, gt, plain, &ev)), (std::vector<int>{0, 0, 0, 1, 0}));
  // Labelled by kind: vessels carry their class, the ignore label follows the last kind.
  GroundTruthVolumes kinds = row();
  kinds.classes = Volume<std::uint8_t>(kinds.fraction.grid);
  const std::uint8_t cls[5] = {0, 2, 0, 1, 2};
  for (int i = 0; i < 5; ++i) kinds.classes.data[i] = cls[i];
  p = LabelPolicy{};
  p.name = "ignore";
  EXPECT_EQ(values(makeLabel(p, kinds, LabelNumbering{true, 3})), (std::vector<int>{0, 3, 3, 3, 2}));
  p.name = "threshold";
  EXPECT_EQ(values(makeLabel(p, kinds, LabelNumbering{true, 3})), (std::vector<int>{0, 0, 0, 1, 2}));
}

// One vessel of radius 0.3 voxel along a row of ten 1 mm voxels, and one of 3 voxels: labels on
// the first four voxels keep 40 % of the thin vessel's length, in the ¼–½ voxel bin.
TEST(LabelPolicy, LengthKeptByCalibreIsTheLabelledShareOfTheCentreline) {
  VolumeGrid g;
  g.dims = {10, 2, 1};
  g.origin_mm = Vec3(0, 0, 0);
  VascularTree t;
  const auto thin_root = t.addNode(Vec3(-0.5, 0, 0), -1, 0);
  const auto thin_end = t.addNode(Vec3(9.5, 0, 0), thin_root, 0);
  const auto thick_root = t.addNode(Vec3(-0.5, 1, 0), -1, 1);
  const auto thick_end = t.addNode(Vec3(9.5, 1, 0), thick_root, 1);
  t.radius[thin_end] = 0.3;
  t.radius[thick_end] = 3;
  Label l;
  l.values = Volume<std::uint8_t>(g);
  for (int i = 0; i < 4; ++i) l.values.at(i, 0, 0) = 1;
  for (int i = 0; i < 10; ++i) l.values.at(i, 1, 0) = i < 9 ? 1 : 2;  // the last voxel: ignore
  LabelPolicy p;
  p.name = "ignore";
  const Json j = Json::parse(labelLengthKept(l, p, LabelNumbering{}, t).dump());
  EXPECT_NEAR(j["length_mm"].get<double>(), 20, 1e-9);
  EXPECT_NEAR(j["vessel"].get<double>(), (4 + 9) / 20.0, 1e-9);
  EXPECT_NEAR(j["ignore"].get<double>(), 1 / 20.0, 1e-9);
  const Json& bins = j["by_calibre"];
  ASSERT_EQ(bins.size(), 6u);
  EXPECT_NEAR(bins[1]["vessel"].get<double>(), 0.4, 1e-9);  // radius 0.3 voxel
  EXPECT_NEAR(bins[4]["vessel"].get<double>(), 0.9, 1e-9);  // radius 3 voxels
  EXPECT_NEAR(bins[4]["ignore"].get<double>(), 0.1, 1e-9);
  EXPECT_TRUE(bins[0]["vessel"].is_null());  // no vessel that thin
}

class LabelPolicyRun : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = freshTestDir("angiosynth_labels_"); }
  void TearDown() override { fs::remove_all(dir_); }
  // A 150-terminal VascuSynth-like tree on 0.8 mm voxels, with two profiles: Gaussian noise only,
  // and blur then noise.
  void writeParams(const std::string& image_keys) {
    std::ofstream(dir_ / "noise.toml") << "background = 20\nvessel = 200\n[[effect]]\ntype = \"gaussian\"\nsigma = 30\n";
    std::ofstream(dir_ / "blurred.toml") << "background = 20\nvessel = 200\n[[effect]]\ntype = \"blur\"\nsigma = \"0.8 mm\"\n"
                                            "[[effect]]\ntype = \"gaussian\"\nsigma = 10\n";
    std::ofstream(dir_ / "p.toml") << "seed = 5\n[domain]\ndemand_map = '" << (src_ / "demand_maps/vascusynth_rods_100.txt").string()
                                   << "'\nsupply_coefficients = [0.65, 0.34, 0.01, 7]\nvoxel_size = \"0.4 mm\"\n"
                                      "[tree]\nterminals = 150\nroot_voxel = [0, 50, 50]\n"
                                      "[physics]\nviscosity = \"3.6 mPa*s\"\nperfusion_pressure = \"13300 Pa\"\n"
                                      "terminal_pressure = \"8300 Pa\"\nperfusion_flow = \"8330 mm3/s\"\n"
                                      "[image]\nvoxel_size = \"0.8 mm\"\ndtype = \"float32\"\n"
                                   << image_keys << "\n[degrade]\nprofiles = [\"noise.toml\", \"blurred.toml\"]\n";
  }
  fs::path dir_;
  const fs::path src_ = ANGIOSYNTH_SOURCE_DIR;
};

// With noise only, the noise-free contrast is (vessel − background) × partial volume, and the
// noise σ is the profile's: the label must be exactly the mask voxels where 180 × fraction ≥
// 2 × σ (fraction recovered from the float clean image). Blur lowers thin vessels' contrast, so
// the blurred profile keeps less of the thinnest vessels than the mask does.
TEST_F(LabelPolicyRun, VisibleLabelIsTheMaskWhereTheNoiseFreeContrastClearsTwoSigma) {
  writeParams("label_policy = \"visible\"\nbackground = 20\nvessel = 200");
  const auto r = run("generate p.toml --out out --quiet", dir_);
  ASSERT_EQ(r.code, 0) << r.err;
  const Json s = Json::parse(slurp(dir_ / "out/sample.json"));
  const double sigma = s["degradation"]["noise"]["label"]["noise_sigma"];
  EXPECT_NEAR(sigma, 30, 0.3);  // 30 drawn; measured on ~100k background voxels
  const std::string out = debianPython(R"(
import nibabel as nib, numpy as np
ld = lambda f: np.asarray(nib.load('out/' + f).dataobj)
pv = (ld('image.nii.gz').astype(np.float64) - 20) / 180
mask, label = ld('mask.nii.gz'), ld('label_noise.nii.gz')
sigma = )" + std::to_string(sigma) + R"(
expected = (mask > 0) & (pv > 0) & (180 * pv >= 2 * sigma * (1 - 1e-6))
print('mismatch', int(((label > 0) != expected).sum()), 'label', int((label > 0).sum()), 'mask', int((mask > 0).sum()),
      'clean_label_is_mask', bool(((ld('label.nii.gz') > 0) == ((mask > 0) & (pv > 0))).all()))
)",
                                       dir_);
  int mismatch = -1, label = 0, mask = 0;
  ASSERT_EQ(std::sscanf(out.c_str(), "mismatch %d label %d mask %d", &mismatch, &label, &mask), 3) << out;
  EXPECT_LE(mismatch, 2) << out;  // float rounding exactly at the threshold at most
  EXPECT_GT(label, 100) << out;
  EXPECT_LT(label, mask) << out;  // not vacuous: noise hides part of the mask
  EXPECT_NE(out.find("clean_label_is_mask True"), std::string::npos) << out;
  // By calibre: the blurred profile keeps less of the thinnest populated bin than the mask does,
  // and every thick vessel.
  const Json& mask_bins = s["statistics"]["label"]["by_calibre"];
  const Json& blur_bins = s["degradation"]["blurred"]["label"]["by_calibre"];
  int thin = -1;
  for (int b = 0; b < 6 && thin < 0; ++b)
    if (!mask_bins[b]["vessel"].is_null() && mask_bins[b]["length_mm"].get<double>() > 5) thin = b;
  ASSERT_GE(thin, 0);
  EXPECT_LT(blur_bins[thin]["vessel"].get<double>(), 0.9 * mask_bins[thin]["vessel"].get<double>());
  EXPECT_GT(blur_bins[4]["vessel"].is_null() ? 1.0 : blur_bins[4]["vessel"].get<double>(), 0.99);
  EXPECT_EQ(s["parameters"]["image"]["label_policy"], "visible");
}

TEST_F(LabelPolicyRun, SameSeedSameLabelsOnOneAndTwoThreads) {
  writeParams("label_policy = \"visible\"");
  ASSERT_EQ(run("generate p.toml --out one --threads 1 --quiet", dir_).code, 0);
  ASSERT_EQ(run("generate p.toml --out two --threads 2 --quiet", dir_).code, 0);
  for (const char* f : {"label.nii.gz", "label_noise.nii.gz", "label_blurred.nii.gz"})
    EXPECT_EQ(slurp(dir_ / "one" / f), slurp(dir_ / "two" / f)) << f;
  const Json a = Json::parse(slurp(dir_ / "one/sample.json")), b = Json::parse(slurp(dir_ / "two/sample.json"));
  EXPECT_EQ(a["degradation"], b["degradation"]);
  EXPECT_EQ(a["statistics"]["label"], b["statistics"]["label"]);
}

// A dataset under the ignore policy: dataset.json declares nnU-Net's ignore label after the
// kinds, labelsTr hold only declared values, vessel voxels lie on the mask, and the layout passes
// the nnU-Net check. Soft labels cannot number kinds.
TEST_F(LabelPolicyRun, DatasetLabelsFollowThePolicyAndDeclareTheIgnoreLabel) {
  std::string spec = slurp(src_ / "tests/data/dataset_av.toml");
  const std::string pinned = "label_policy = \"binary\"";
  ASSERT_NE(spec.find(pinned), std::string::npos);
  spec.replace(spec.find(pinned), pinned.size(), "label_policy = \"ignore\"");
  fs::copy_file(src_ / "tests/data/profile_warp.toml", dir_ / "profile_warp.toml");
  std::ofstream(dir_ / "spec.toml") << spec;
  const auto r = run("dataset spec.toml --out raw --quiet", dir_);
  ASSERT_EQ(r.code, 0) << r.err;
  const fs::path ds = dir_ / "raw/Dataset903_ArteryVeinTiny";
  const Json dj = Json::parse(slurp(ds / "dataset.json"));
  EXPECT_EQ(dj["labels"], (Json{{"background", 0}, {"vein", 1}, {"artery", 2}, {"ignore", 3}}));
  EXPECT_EQ(dj["label_policy"], "ignore");
  const std::string cmd =
      "/usr/bin/python3 '" + (src_ / "tests/check_nnunet.py").string() + "' '" + ds.string() + "' > '" + (dir_ / "check.txt").string() + "' 2>&1";
  EXPECT_EQ(std::system(cmd.c_str()), 0) << slurp(dir_ / "check.txt");
  const std::string out = debianPython(R"(
import glob, os
import nibabel as nib, numpy as np
for lab in sorted(glob.glob('labelsTr/*.nii.gz')):
    case = os.path.basename(lab)[:-7]
    g = 'groundtruth/' + case
    l = np.asarray(nib.load(lab).dataobj)
    # labelsTr holds the label of the image's profile (moved there): the warped one for the
    # profile that warps, else the clean one (cta moves nothing).
    warped = os.path.exists(g + '/mask_profile_warp.nii.gz')
    moved = not os.path.exists(g + ('/label_profile_warp.nii.gz' if warped else '/label.nii.gz'))
    mask = np.asarray(nib.load(g + ('/mask_profile_warp.nii.gz' if warped else '/mask.nii.gz')).dataobj)
    print(case, 'values', sorted(int(v) for v in np.unique(l)), 'moved', moved,
          'vessel_on_mask', bool((mask[(l == 1) | (l == 2)] > 0).all()))
)",
                                       ds);
  for (const char* c : {"ArteryVeinTiny_0000", "ArteryVeinTiny_0001"}) {
    const auto at = out.find(c);
    ASSERT_NE(at, std::string::npos) << out;
    const std::string line = out.substr(at, out.find('\n', at) - at);
    EXPECT_NE(line.find("values [0, 1, 2, 3] moved True vessel_on_mask True"), std::string::npos) << line;
  }
  spec.replace(spec.find("label_policy = \"ignore\""), 23, "label_policy = \"soft\"");
  std::ofstream(dir_ / "soft.toml") << spec;
  const auto bad = run("dataset soft.toml --out raw2 --quiet", dir_);
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.err.find("soft.toml:"), std::string::npos) << bad.err;
  EXPECT_NE(bad.err.find("cannot number kinds"), std::string::npos) << bad.err;
  EXPECT_FALSE(fs::exists(dir_ / "raw2"));
}

}  // namespace
