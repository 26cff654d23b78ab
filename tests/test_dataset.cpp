// Datasets: sample bytes independent of how they were made, the nnU-Net layout, describe,
// verify and resume, failures.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fstream>
#include <map>
#include <sstream>

#include <toml++/toml.h>

#include "cli_run.hpp"
#include "dataset/manifest.hpp"
#include "dataset/spec.hpp"

namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

// A path in single quotes for a shell command line (appended piecewise: GCC 12 warns falsely,
// -Wrestrict, on "'" + string + "'").
std::string quoted(const fs::path& p) {
  std::string s(1, '\'');
  s += p.string();
  s += '\'';
  return s;
}

class Dataset : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = freshTestDir("angiosynth_ds_"); }
  void TearDown() override { fs::remove_all(dir_); }
  // path → sha256 of every file of every sample, per index.
  static std::map<std::int64_t, std::map<std::string, std::string>> hashes(const fs::path& ds) {
    std::map<std::int64_t, std::map<std::string, std::string>> out;
    for (const auto& [i, e] : angiosynth::readManifests(ds))
      for (const auto& f : e["files"]) out[i][f["path"]] = f["sha256"];
    return out;
  }
  fs::path dir_;
  const fs::path src_ = ANGIOSYNTH_SOURCE_DIR;
  const std::string spec_ = quoted(src_ / "tests/data/dataset_tiny.toml");
  const std::string name_ = "Dataset902_VesselTiny";
};

TEST_F(Dataset, SampleBytesAreTheSameAloneInAFullRunInAnyShardAndForAnyThreads) {
  ASSERT_EQ(run("dataset " + spec_ + " --out full2 --threads 2 --quiet", dir_).code, 0);
  ASSERT_EQ(run("dataset " + spec_ + " --out full1 --threads 1 --quiet", dir_).code, 0);
  ASSERT_EQ(run("dataset " + spec_ + " --out alone --index 4 --quiet", dir_).code, 0);
  ASSERT_EQ(run("dataset " + spec_ + " --out shard --shard 1/2 --quiet", dir_).code, 0);
  ASSERT_EQ(run("dataset " + spec_ + " --out range --range 2:5 --quiet", dir_).code, 0);
  const auto full = hashes(dir_ / "full2" / name_);
  ASSERT_EQ(full.size(), 6u);
  EXPECT_EQ(hashes(dir_ / "full1" / name_), full);
  const auto alone = hashes(dir_ / "alone" / name_);
  ASSERT_EQ(alone.size(), 1u);
  EXPECT_EQ(alone.at(4), full.at(4));
  const auto shard = hashes(dir_ / "shard" / name_);
  ASSERT_EQ(shard.size(), 3u);  // 1, 3, 5
  for (const auto& [i, files] : shard) EXPECT_EQ(files, full.at(i)) << i;
  const auto range = hashes(dir_ / "range" / name_);
  ASSERT_EQ(range.size(), 3u);  // 2, 3, 4
  for (const auto& [i, files] : range) EXPECT_EQ(files, full.at(i)) << i;
  // Not vacuous: samples differ from each other, and each holds the nnU-Net pair.
  EXPECT_NE(full.at(0).at("imagesTr/VesselTiny_0000_0000.nii.gz"), full.at(1).at("imagesTr/VesselTiny_0001_0000.nii.gz"));
  EXPECT_TRUE(full.at(3).count("labelsTr/VesselTiny_0003.nii.gz"));
  // Shards merged by finalize make the same dataset as a full run.
  ASSERT_EQ(run("dataset " + spec_ + " --out merged --shard 0/2 --quiet", dir_).code, 0);
  ASSERT_EQ(run("dataset " + spec_ + " --out merged --shard 1/2 --quiet", dir_).code, 0);
  ASSERT_EQ(run("dataset finalize merged/" + name_, dir_).code, 0);
  EXPECT_EQ(hashes(dir_ / "merged" / name_), full);
  EXPECT_EQ(slurp(dir_ / "merged" / name_ / "dataset.json"), slurp(dir_ / "full2" / name_ / "dataset.json"));
  // The cluster scripts' way: shard K from Slurm's or Kubernetes' index variable.
  for (const std::string env : {"SLURM_ARRAY_TASK_ID=0", "JOB_COMPLETION_INDEX=1"}) {
    const std::string cmd = "cd '" + dir_.string() + "' && env -u SLURM_ARRAY_TASK_ID -u JOB_COMPLETION_INDEX " + env + " '" + ANGIOSYNTH_EXE +
                            "' dataset " + spec_ + " --out cluster --shard auto/2 --quiet >/dev/null 2>&1";
    ASSERT_EQ(std::system(cmd.c_str()), 0) << env;
  }
  ASSERT_EQ(run("dataset finalize cluster/" + name_, dir_).code, 0);
  EXPECT_EQ(hashes(dir_ / "cluster" / name_), full);
}

TEST_F(Dataset, LayoutObeysTheRulesNnUNetChecks) {
  ASSERT_EQ(run("dataset " + spec_ + " --out raw --quiet", dir_).code, 0);
  const fs::path ds = dir_ / "raw" / name_;
  const std::string cmd =
      "/usr/bin/python3 '" + (src_ / "tests/check_nnunet.py").string() + "' '" + ds.string() + "' > '" + (dir_ / "check.txt").string() + "' 2>&1";
  EXPECT_EQ(std::system(cmd.c_str()), 0) << slurp(dir_ / "check.txt");
  EXPECT_NE(slurp(dir_ / "check.txt").find("6 cases checked, 0 problems"), std::string::npos) << slurp(dir_ / "check.txt");
  const Json j = Json::parse(slurp(ds / "dataset.json"));
  EXPECT_EQ(j["channel_names"]["0"], "angio");
  EXPECT_EQ(j["numTraining"], 6);
  for (const char* f :
       {"manifest.jsonl", "provenance.json", "groundtruth/VesselTiny_0002.json", "groundtruth/VesselTiny_0002/centerline.nii.gz",
        "groundtruth/VesselTiny_0002/radius.nii.gz", "groundtruth/VesselTiny_0002/instances.nii.gz", "groundtruth/VesselTiny_0002/keypoints.csv",
        "groundtruth/VesselTiny_0002/tree.gxl", "groundtruth/VesselTiny_0002/image.nii.gz"})
    EXPECT_TRUE(fs::exists(ds / f)) << f;
  const Json prov = Json::parse(slurp(ds / "provenance.json"));
  EXPECT_NE(prov["spec"].get<std::string>().find("VesselTiny"), std::string::npos);
  EXPECT_EQ(prov["runs"].size(), 1u);
  // The data's licence and how to cite the tool, and no host name unless the spec asks for one.
  EXPECT_EQ(j["licence"], "CC0-1.0");
  EXPECT_NE(j["reference"].get<std::string>().find("CITATION.cff"), std::string::npos);
  EXPECT_EQ(prov["licence"], "CC0-1.0");
  EXPECT_FALSE(prov["finalized_on"].contains("hostname"));
  EXPECT_FALSE(prov["runs"][0]["machine"].contains("hostname"));
  EXPECT_TRUE(prov["runs"][0]["machine"].contains("cores"));
  // Every manifest line names its files with size and hash.
  std::ifstream in(ds / "manifest.jsonl");
  int lines = 0;
  for (std::string l; std::getline(in, l); ++lines) {
    const Json e = Json::parse(l);
    EXPECT_EQ(e["status"], "ok");
    EXPECT_GE(e["files"].size(), 10u);
    EXPECT_EQ(e["files"][0]["sha256"].get<std::string>().size(), 64u);
  }
  EXPECT_EQ(lines, 6);
}

// The spec names the data's licence and may ask for the host names.
TEST_F(Dataset, TheSpecNamesTheLicenceAndMayRecordTheHost) {
  std::string text = slurp(src_ / "tests/data/dataset_tiny.toml");
  text.replace(text.find("../../demand_maps"), 17, (src_ / "demand_maps").string());
  text.replace(text.find("channel_name"), 0, "licence = \"CC-BY-4.0\"\nrecord_host = true\n");
  std::ofstream(dir_ / "tiny_licence.toml") << text;
  ASSERT_EQ(run("dataset tiny_licence.toml --out l --quiet", dir_).code, 0);
  EXPECT_EQ(Json::parse(slurp(dir_ / "l" / name_ / "dataset.json"))["licence"], "CC-BY-4.0");
  const Json prov = Json::parse(slurp(dir_ / "l" / name_ / "provenance.json"));
  EXPECT_EQ(prov["licence"], "CC-BY-4.0");
  EXPECT_TRUE(prov["finalized_on"].contains("hostname"));
  EXPECT_TRUE(prov["runs"][0]["machine"].contains("hostname"));
  const auto licence = text.find("\"CC-BY-4.0\"");
  ASSERT_NE(licence, std::string::npos);
  text = text.substr(0, licence) + "\"\"" + text.substr(licence + 11);
  std::ofstream(dir_ / "tiny_licence.toml") << text;
  const auto bad = run("dataset tiny_licence.toml --out m --quiet", dir_);
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.err.find("licence must be a text of 1 to 200 characters"), std::string::npos) << bad.err;
}

// previews = true: MIPs of the clean and the degraded image beside each sample's ground truth,
// none in nnU-Net's folders.
TEST_F(Dataset, PreviewsPutMipsInTheGroundTruthOnly) {
  std::string text = slurp(src_ / "tests/data/dataset_tiny.toml");
  text.replace(text.find("../../demand_maps"), 17, (src_ / "demand_maps").string());
  text.replace(text.find("channel_name"), 0, "previews = true\n");
  std::ofstream(dir_ / "tiny_previews.toml") << text;
  ASSERT_EQ(run("dataset tiny_previews.toml --out p --index 2 --quiet", dir_).code, 0);
  const fs::path gt = dir_ / "p" / name_ / "groundtruth/VesselTiny_0002";
  const Json meta = Json::parse(slurp(dir_ / "p" / name_ / "groundtruth/VesselTiny_0002.json"));
  const std::string profile = meta["profile"];
  for (const std::string& f : std::vector<std::string>{"mip_x.png", "mip_y.png", "mip_z.png", "mip_z_" + profile + ".png"})
    EXPECT_TRUE(fs::exists(gt / f)) << f;
  for (const char* sub : {"imagesTr", "labelsTr"})
    for (const auto& e : fs::directory_iterator(dir_ / "p" / name_ / sub)) EXPECT_NE(e.path().extension(), ".png") << e.path();
}

TEST_F(Dataset, DescribeShowsTheParametersTheSampleIsMadeFrom) {
  ASSERT_EQ(run("dataset " + spec_ + " --out raw --index 3 --quiet", dir_).code, 0);
  const std::string cmd = quoted(ANGIOSYNTH_EXE) + " dataset describe " + spec_ + " --index 3 > " + quoted(dir_ / "d.txt");
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  const std::string described = slurp(dir_ / "d.txt");
  const Json meta = Json::parse(slurp(dir_ / "raw" / name_ / "groundtruth/VesselTiny_0003.json"));
  // The same parameters, each number in its shortest form (0.65, not 0.65000000000000002).
  const auto described_table = toml::parse(std::string_view(described), std::string_view("described"));
  const std::string made_text = meta["parameters_toml"].get<std::string>();
  const auto made_table = toml::parse(std::string_view(made_text), std::string_view("made"));
  EXPECT_TRUE(described_table == made_table) << described;
  std::istringstream lines(described);
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("seed", 0) == 0 || line.rfind('#', 0) == 0) continue;  // the 19-digit seed
    std::size_t run_of_digits = 0, longest = 0;
    for (char c : line) longest = std::max(longest, run_of_digits = std::isdigit(static_cast<unsigned char>(c)) ? run_of_digits + 1 : 0);
    EXPECT_LT(longest, 17u) << line;
  }
  EXPECT_EQ(described.rfind("# sample 3 (VesselTiny_0003), seed " + std::to_string(meta["seed"].get<std::uint64_t>()), 0), 0u);
}

TEST_F(Dataset, VerifyFindsCorruptAndMissingFilesAndResumeRepairsOnlyThose) {
  ASSERT_EQ(run("dataset " + spec_ + " --out raw --quiet", dir_).code, 0);
  const fs::path ds = dir_ / "raw" / name_;
  ASSERT_EQ(run("dataset verify raw/" + name_, dir_).code, 0);
  {
    std::fstream f(ds / "labelsTr/VesselTiny_0002.nii.gz", std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(100);
    f.put('\x5a');
  }
  fs::remove(ds / "groundtruth/VesselTiny_0004/radius.nii.gz");
  const auto v = run("dataset verify raw/" + name_, dir_);
  EXPECT_EQ(v.code, 1);
  EXPECT_NE(v.err.find("corrupt VesselTiny_0002: labelsTr/VesselTiny_0002.nii.gz"), std::string::npos) << v.err;
  EXPECT_NE(v.err.find("missing file of VesselTiny_0004: groundtruth/VesselTiny_0004/radius.nii.gz"), std::string::npos) << v.err;
  const auto r = run("dataset " + spec_ + " --out raw --resume", dir_);
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("2 generated, 4 skipped (verified), 0 failed"), std::string::npos) << r.err;
  EXPECT_EQ(run("dataset verify raw/" + name_, dir_).code, 0);
}

TEST_F(Dataset, FailedSamplesAreRecordedAndMakeTheExitCodeNonZero) {
  std::string t = slurp(src_ / "tests/data/dataset_tiny.toml");
  t.replace(t.find("root_voxel"), 0, "min_distance = {choice = [\"1 voxel\", \"60 voxel\"]}\n");
  t.replace(t.find("../../demand_maps"), 17, (src_ / "demand_maps").string());
  std::ofstream(dir_ / "spec.toml") << t;
  const auto r = run("dataset spec.toml --out raw --quiet", dir_);
  EXPECT_EQ(r.code, 1) << r.err;
  const auto entries = angiosynth::readManifests(dir_ / "raw" / name_);
  int failed = 0, ok = 0;
  for (const auto& [i, e] : entries) {
    if (e["status"] == "failed") {
      ++failed;
      EXPECT_NE(e["error"].get<std::string>().find("cannot lie"), std::string::npos) << e.dump();
      EXPECT_FALSE(fs::exists(dir_ / "raw" / name_ / "imagesTr" / (e["id"].get<std::string>() + "_0000.nii.gz")));
    } else {
      ++ok;
    }
  }
  EXPECT_GT(failed, 0);
  EXPECT_GT(ok, 0);
  const Json j = Json::parse(slurp(dir_ / "raw" / name_ / "dataset.json"));
  EXPECT_EQ(j["numTraining"], ok);
  const auto v = run("dataset verify raw/" + name_, dir_);
  EXPECT_EQ(v.code, 1);
  EXPECT_NE(v.err.find("failed VesselTiny_"), std::string::npos) << v.err;
}

// labels = "kind": labelsTr holds one label per kind, numbered as [dataset] kinds lists them
// (vein 1, artery 2 here) in every sample; each tree's root voxel carries its kind's label; the
// label covers the mask of the image it belongs to (the warped one for the profile file that
// warps), and imagesTr holds that profile's image, not the clean one.
TEST_F(Dataset, KindLabelsNumberEachKindAsTheSpecListsItAndFollowTheWarpedImage) {
  ASSERT_EQ(run("dataset " + quoted(src_ / "tests/data/dataset_av.toml") + " --out raw --quiet", dir_).code, 0);
  const fs::path ds = dir_ / "raw" / "Dataset903_ArteryVeinTiny";
  const std::string cmd =
      "/usr/bin/python3 '" + (src_ / "tests/check_nnunet.py").string() + "' '" + ds.string() + "' > '" + (dir_ / "check.txt").string() + "' 2>&1";
  EXPECT_EQ(std::system(cmd.c_str()), 0) << slurp(dir_ / "check.txt");
  const Json labels = Json::parse(slurp(ds / "dataset.json"))["labels"];
  EXPECT_EQ(labels, (Json{{"background", 0}, {"vein", 1}, {"artery", 2}}));
  const std::string out = debianPython(R"(
import csv, glob, json, os
import nibabel as nib, numpy as np
warped = 0
for lab in sorted(glob.glob('labelsTr/*.nii.gz')):
    case = os.path.basename(lab)[:-7]
    g = 'groundtruth/' + case
    l = np.asarray(nib.load(lab).dataobj)
    meta = json.load(open(g + '.json'))
    sample = json.load(open(g + '/sample.json'))
    warp = [f for f in os.listdir(g) if f.startswith('mask_')]
    warped += len(warp)
    mask = np.asarray(nib.load(g + '/' + (warp[0] if warp else 'mask.nii.gz')).dataobj)
    image = np.asarray(nib.load('imagesTr/' + case + '_0000.nii.gz').dataobj)
    clean = np.asarray(nib.load(g + '/image.nii.gz').dataobj)
    roots = {r['kind']: tuple(int(np.floor(float(r[a + '_voxel']) + 0.5)) for a in 'xyz')
             for r in csv.DictReader(open(g + '/keypoints.csv')) if r['type'] == 'root'}
    print(case, 'values', sorted(int(v) for v in np.unique(l)), 'legend', sample['classes']['1'], sample['classes']['2'],
          'meta', meta['label_values']['vein'], meta['label_values']['artery'],
          'roots', *((int(l[roots['vein']]), int(l[roots['artery']])) if not warp else ('moved', 'by the warp')),
          'on mask', bool(((l > 0) == (mask > 0)).all()), 'image', 'clean' if np.array_equal(image, clean) else 'degraded')
print('warped', warped)
)",
                                       ds);
  for (const char* c : {"ArteryVeinTiny_0000", "ArteryVeinTiny_0001", "ArteryVeinTiny_0002"}) {
    const auto at = out.find(c);
    ASSERT_NE(at, std::string::npos) << out;
    const std::string line = out.substr(at, out.find('\n', at) - at);
    EXPECT_NE(line.find("values [0, 1, 2] legend vein artery meta 1 2"), std::string::npos) << line;
    EXPECT_NE(line.find("on mask True image degraded"), std::string::npos) << line;
    if (line.find("roots moved") == std::string::npos) { EXPECT_NE(line.find("roots 1 2"), std::string::npos) << line; }
  }
  EXPECT_EQ(out.find("warped 0"), std::string::npos) << out;  // the spec's profile file warps
}

TEST_F(Dataset, BadSpecsNameFileAndLine) {
  std::ofstream(dir_ / "bad.toml") << "[dataset]\nname = \"a.b\"\nid = 1\nsamples = 2\nseed = 1\n";
  auto r = run("dataset bad.toml --out raw", dir_);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("bad.toml:2: name must be letters, digits"), std::string::npos) << r.err;
  // A float beyond int64 where a whole number belongs (a fuzz finding: the TOML library's own
  // conversion of it is undefined behaviour).
  std::ofstream(dir_ / "bad1.toml") << "[dataset]\nname = \"a\"\nid = 1\nsamples = 2\nseed = 2.0e26\n";
  r = run("dataset bad1.toml --out raw", dir_);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("bad1.toml:5: seed must be a whole number >= 0"), std::string::npos) << r.err;
  std::string t = slurp(src_ / "tests/data/dataset_tiny.toml");
  t.replace(t.find("{integer = [60, 160]}"), 21, "{integer = [60, 160], max = 3}");
  std::ofstream(dir_ / "bad2.toml") << t;
  r = run("dataset bad2.toml --out raw", dir_);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("unknown key 'max' in a distribution"), std::string::npos) << r.err;
  // Labels by kind: a mode that does not exist, kinds without that mode, and a sample growing a
  // kind the list leaves out (line 10: kinds).
  std::string av = slurp(src_ / "tests/data/dataset_av.toml");
  fs::copy_file(src_ / "tests/data/profile_warp.toml", dir_ / "profile_warp.toml");
  const auto with = [&](const std::string& from, const std::string& to) {
    std::string t = av;
    t.replace(t.find(from), from.size(), to);
    std::ofstream(dir_ / "bad3.toml") << t;
    return run("dataset bad3.toml --out raw", dir_);
  };
  r = with("labels = \"kind\"", "labels = \"kinds\"");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("bad3.toml:9: labels must be \"binary\" (vessel 1) or \"kind\""), std::string::npos) << r.err;
  r = with("labels = \"kind\"", "labels = \"binary\"");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("bad3.toml:10: kinds numbers the labels of labels = \"kind\""), std::string::npos) << r.err;
  r = with("kinds = [\"vein\", \"artery\"]", "kinds = [\"artery\"]");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("bad3.toml:10: the sample grows a tree of kind 'vein', which has no label: kinds = [artery]"), std::string::npos) << r.err;
  r = with("kinds = [\"vein\", \"artery\"]", "kinds = [\"vein\", \"vein\"]");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("bad3.toml:10: kinds must be a list of distinct kind names"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "raw"));
}

}  // namespace
