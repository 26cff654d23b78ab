// Safety: the program deletes only what it wrote, interrupted runs leave nothing, and
// datasets stay whole under concurrent shards, torn or hostile manifests and edited specs.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <map>
#include <set>
#include <thread>

#include "cli_run.hpp"
#include "core/interrupt_cleanup.hpp"
#include "dataset/manifest.hpp"

namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

// Every file below `dir` (relative path → content), to show that nothing was lost or changed;
// stderr.txt is the test's own capture of the program's messages.
std::map<std::string, std::string> snapshot(const fs::path& dir) {
  std::map<std::string, std::string> out;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file() && e.path().filename() != "stderr.txt") out[fs::relative(e.path(), dir).string()] = slurp(e.path());
  return out;
}

class Safety : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = freshTestDir("angiosynth_safety_");
    // A self-contained VascuSynth-like parameter file (absolute map path), small and quick.
    std::string t = selfContained(src_ / "examples/vascusynth_like.toml");
    replaceOnce(t, "terminals = 1000", "terminals = 60");
    replaceOnce(t, "profiles = [\"vascusynth\", \"cta\"]", "profiles = []");
    work_ = dir_ / "work";
    fs::create_directories(work_ / "notes");
    std::ofstream(work_ / "params.toml") << t;
    std::ofstream(work_ / "notes" / "mine.txt") << "the user's own file\n";
    std::ofstream(work_ / "thesis.tex") << "\\documentclass{article}\n";
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_, work_;
  const fs::path src_ = ANGIOSYNTH_SOURCE_DIR;
};

TEST_F(Safety, OutputThatIsOrContainsTheWorkingDirectoryOrAnInputIsRefusedAndNothingIsDeleted) {
  const auto before = snapshot(dir_);
  for (const std::string& out : std::vector<std::string>{".", "./", "..", work_.string(), dir_.string(), "/"}) {
    const auto r = run("generate params.toml --out '" + out + "' --force --no-image --quiet", work_);
    EXPECT_EQ(r.code, 2) << out << ": " << r.err;
    EXPECT_NE(r.err.find("refuses to write there"), std::string::npos) << r.err;
    EXPECT_EQ(snapshot(dir_), before) << out;
  }
  // An output directory holding an input (the parameter file lives in notes/ here).
  fs::copy_file(work_ / "params.toml", work_ / "notes" / "p.toml");
  const auto r = run("generate notes/p.toml --out notes --force --no-image --quiet", work_);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("contains the input"), std::string::npos) << r.err;
  EXPECT_TRUE(fs::exists(work_ / "notes" / "mine.txt"));
  // A file given as --out.
  const auto f = run("generate params.toml --out thesis.tex --no-image --quiet", work_);
  EXPECT_EQ(f.code, 2);
  EXPECT_NE(f.err.find("is a file, not a directory"), std::string::npos) << f.err;
}

TEST_F(Safety, ForceReplacesOnlyAngiosynthsOwnFiles) {
  // A directory of the user's: --force does not touch it.
  auto r = run("generate params.toml --out notes --force --no-image --quiet", work_);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("did not write"), std::string::npos) << r.err;
  EXPECT_EQ(fs::directory_iterator(work_ / "notes")->path().filename(), "mine.txt");
  // An earlier output of ours: replaced, but a file the user added there survives; files of the
  // earlier run that this run does not write (here: volumes) are removed.
  ASSERT_EQ(run("generate params.toml --out out --quiet --format nifti", work_).code, 0);
  ASSERT_TRUE(fs::exists(work_ / "out" / "image.nii.gz"));
  std::ofstream(work_ / "out" / "my_notes.txt") << "keep me\n";
  ASSERT_EQ(run("generate params.toml --out out --force --no-image --quiet", work_).code, 0);
  EXPECT_EQ(slurp(work_ / "out" / "my_notes.txt"), "keep me\n");
  EXPECT_FALSE(fs::exists(work_ / "out" / "image.nii.gz"));
  EXPECT_TRUE(fs::exists(work_ / "out" / "tree.gxl"));
  const auto record = Json::parse(slurp(work_ / "out" / ".angiosynth-files.json"));
  std::set<std::string> listed(record["files"].begin(), record["files"].end());
  EXPECT_TRUE(listed.count("tree.gxl"));
  EXPECT_FALSE(listed.count("my_notes.txt"));
  // Without --force an existing output is refused and left alone.
  EXPECT_EQ(run("generate params.toml --out out --no-image --quiet", work_).code, 2);
  EXPECT_TRUE(fs::exists(work_ / "out" / "my_notes.txt"));
}

TEST_F(Safety, VascuSynthRerunsOverwriteTheirFilesAndLeaveTheUsersAndRefuseDotNames) {
  const std::string params = (src_ / "examples/vascusynth/param_rods_1000.txt").string();
  std::string p = selfContained(params);
  replaceOnce(p, "NUM_NODES: 1000", "NUM_NODES: 50");
  std::ofstream(work_ / "p.txt") << p;
  std::ofstream(work_ / "params.txt") << "p.txt\n";
  std::ofstream(work_ / "names.txt") << "img\n";
  std::ofstream(work_ / "noise.txt") << "GAUSSIAN: 0 10\n";
  ASSERT_EQ(run("vascusynth params.txt names.txt 0.04 noise.txt --quiet", work_).code, 0);
  ASSERT_TRUE(fs::exists(work_ / "img" / "noise_image_0"));
  std::ofstream(work_ / "img" / "mynotes.txt") << "mine\n";
  // Again without the noise file: our noise image goes, the user's notes stay.
  ASSERT_EQ(run("vascusynth params.txt names.txt 0.04 --quiet", work_).code, 0);
  EXPECT_EQ(slurp(work_ / "img" / "mynotes.txt"), "mine\n");
  EXPECT_TRUE(fs::exists(work_ / "img" / "tree_structure.xml"));
  EXPECT_FALSE(fs::exists(work_ / "img" / "noise_image_0"));
  // A name that is the working directory (or its parent) is refused before anything is grown.
  const auto before = snapshot(dir_);
  for (const std::string& name : std::vector<std::string>{".", "..", "img/.."}) {
    std::ofstream(work_ / "names.txt") << name << "\n";
    const auto before_names = snapshot(dir_);
    const auto r = run("vascusynth params.txt names.txt 0.04 --quiet", work_);
    EXPECT_EQ(r.code, 2) << name;
    EXPECT_NE(r.err.find("names.txt:1:"), std::string::npos) << r.err;
    EXPECT_EQ(snapshot(dir_), before_names) << name;
  }
  // A bad map in the second parameter file: nothing written for the first either.
  std::string bad = p;
  replaceOnce(bad, "vascusynth_rods_100.txt", "no_such_map.txt");
  std::ofstream(work_ / "bad.txt") << bad;
  std::ofstream(work_ / "params.txt") << "p.txt\nbad.txt\n";
  std::ofstream(work_ / "names.txt") << "first\nsecond\n";
  const auto r = run("vascusynth params.txt names.txt 0.04 --quiet", work_);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_FALSE(fs::exists(work_ / "first"));
}

TEST_F(Safety, AnInterruptRemovesTheStagingDirectory) {
  // The 4000-terminal sphere runs about 2 s: long enough to be interrupted while growing.
  const std::string cmd = std::string(ANGIOSYNTH_EXE) + " generate " + (src_ / "examples/cco_sphere_3d.toml").string() + " --out " +
                          (work_ / "big").string() + " --quiet";
  for (const int sig : {SIGINT, SIGTERM}) {
    const pid_t pid = fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
      execl("/bin/sh", "sh", "-c", ("exec " + cmd).c_str(), nullptr);
      _exit(127);
    }
    bool staged = false;  // wait until the staging directory exists, then interrupt
    for (int i = 0; i < 400 && !staged; ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
      for (const auto& e : fs::directory_iterator(work_)) staged |= e.path().filename().string().rfind(".big.tmp-", 0) == 0;
    }
    EXPECT_TRUE(staged);
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    kill(pid, sig);
    int status = 0;
    waitpid(pid, &status, 0);
    EXPECT_TRUE(WIFEXITED(status)) << sig;
    EXPECT_EQ(WEXITSTATUS(status), 128 + sig);
    for (const auto& e : fs::directory_iterator(work_)) EXPECT_EQ(e.path().filename().string().find("big"), std::string::npos) << e.path();
  }
}

TEST_F(Safety, StagingLeftByAKilledProcessIsRemovedByTheNextRunAndOthersAreKept) {
  // A dead process of this host (pid far above pid_max is never alive), one of another host, and a
  // directory that only looks like staging (no marker): only the first is ours to remove.
  const std::string host = angiosynth::stagingSuffix().substr(0, angiosynth::stagingSuffix().rfind('-'));
  const fs::path dead = work_ / (".out.tmp-" + host + "-99999999"), other = work_ / ".out.tmp-otherhost-12",
                 lookalike = work_ / (".out.tmp-" + host + "-99999998");
  for (const auto& d : {dead, other}) {
    fs::create_directories(d);
    std::ofstream(d / ".angiosynth-staging") << "\n";
  }
  fs::create_directories(lookalike);
  ASSERT_EQ(run("generate params.toml --out out --no-image --quiet", work_).code, 0);
  EXPECT_FALSE(fs::exists(dead));
  EXPECT_TRUE(fs::exists(other));
  EXPECT_TRUE(fs::exists(lookalike));
}

// Datasets --------------------------------------------------------------------------------------

class SafeDataset : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = freshTestDir("angiosynth_safeds_");
    std::string t = selfContained(src_ / "tests/data/dataset_tiny.toml");
    replaceOnce(t, "samples = 6", "samples = 16");
    replaceOnce(t, "integer = [60, 160]", "integer = [20, 60]");
    text_ = t;
    std::ofstream(dir_ / "spec.toml") << t;
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::map<std::string, std::string> sampleHashes(const fs::path& ds) {
    std::map<std::string, std::string> out;
    for (const auto& [i, e] : angiosynth::readManifests(ds))
      for (const auto& f : e["files"]) out[f["path"]] = f["sha256"];
    return out;
  }
  fs::path dir_;
  std::string text_;
  const fs::path src_ = ANGIOSYNTH_SOURCE_DIR;
  const std::string name_ = "Dataset902_VesselTiny";
};

TEST_F(SafeDataset, ConcurrentShardsLoseNoSampleAndMatchASingleProcessRun) {
  ASSERT_EQ(run("dataset spec.toml --out single --quiet", dir_).code, 0);
  EXPECT_FALSE(fs::exists(dir_ / "single" / name_ / ".staging"));  // a finished dataset holds only its files
  const auto single = sampleHashes(dir_ / "single" / name_);
  ASSERT_GT(single.size(), 16u * 3);  // image, label, meta and ground truth per sample
  for (int round = 0; round < 6; ++round) {
    const std::string out = "conc" + std::to_string(round);
    const int shards = 2 + round % 2;  // 2 or 3 shards at once, one thread each
    std::string cmd = "cd '" + dir_.string() + "' && (";
    for (int k = 0; k < shards; ++k)
      cmd += std::string(ANGIOSYNTH_EXE) + " dataset spec.toml --out " + out + " --shard " + std::to_string(k) + "/" + std::to_string(shards) +
             " --threads 1 --quiet >/dev/null 2>>err.txt & ";
    cmd += "wait)";
    ASSERT_EQ(std::system(cmd.c_str()), 0);
    ASSERT_EQ(run("dataset finalize " + out + "/" + name_, dir_).code, 0) << slurp(dir_ / "stderr.txt");
    ASSERT_EQ(run("dataset verify " + out + "/" + name_, dir_).code, 0) << slurp(dir_ / "stderr.txt");
    EXPECT_EQ(sampleHashes(dir_ / out / name_), single) << "round " << round;
    EXPECT_FALSE(fs::exists(dir_ / out / name_ / ".staging"));  // the last shard to finish removes it
  }
  EXPECT_EQ(slurp(dir_ / "err.txt"), "");
}

TEST_F(SafeDataset, ATornManifestLineIsCutOffAndItsSampleRedone) {
  ASSERT_EQ(run("dataset spec.toml --out raw --quiet", dir_).code, 0);
  const fs::path ds = dir_ / "raw" / name_, part = ds / "manifest" / "all.jsonl";
  fs::remove(ds / "manifest.jsonl");
  // The last entry loses its end (a kill during the write) and its sample's image is gone.
  std::string text = slurp(part);
  const auto last = text.rfind('\n', text.size() - 2) + 1;
  const auto entry = Json::parse(text.substr(last));
  text.resize(last + (text.size() - last) / 2);
  std::ofstream(part, std::ios::trunc) << text;
  fs::remove(ds / entry["files"][0]["path"].get<std::string>());
  const auto v = run("dataset verify raw/" + name_, dir_);
  EXPECT_EQ(v.code, 1);
  EXPECT_NE(v.err.find("manifest/all.jsonl:16: not valid JSON (a torn last line"), std::string::npos) << v.err;
  ASSERT_EQ(run("dataset spec.toml --out raw --resume --quiet", dir_).code, 0);
  // Every line parses again, and the dataset verifies.
  std::ifstream in(part);
  int lines = 0;
  for (std::string l; std::getline(in, l); ++lines) EXPECT_FALSE(Json::parse(l, nullptr, false).is_discarded()) << l;
  EXPECT_EQ(lines, 16);
  EXPECT_EQ(run("dataset verify raw/" + name_, dir_).code, 0) << slurp(dir_ / "stderr.txt");
}

TEST_F(SafeDataset, MalformedAndEscapingManifestLinesAreReportedAndBlockNothing) {
  ASSERT_EQ(run("dataset spec.toml --out raw --quiet", dir_).code, 0);
  const fs::path ds = dir_ / "raw" / name_;
  std::ofstream part(ds / "manifest" / "evil.jsonl");
  part << R"({"index": 3, "status": "ok"})"
       << "\n"  // no files
       << R"({"index": 3, "status": "ok", "files": [{"sha256": "00"}]})"
       << "\n"  // no path
       << R"({"index": "3", "status": "ok", "files": []})"
       << "\n"  // index a string
       << R"({"index": 99999999999, "status": "failed"})"
       << "\n"  // out of range
       << R"({"index": 2, "status": 7})"
       << "\n"  // wrong type
       << R"({"index": 2, "status": "ok", "finished_unix": 1e300, "files": [{"path": "../../../../etc/hostname", "size": 3, "sha256": ")"
       << std::string(64, 'a') << "\"}]}\n"
       << "[1, 2, 3]\n"
       << R"({"index":0,"status":"ok","files":8,"status":"failed","error":"x"})"
       << "\n";  // found by fuzz_manifest
  part.close();
  const auto v = run("dataset verify raw/" + name_, dir_);
  EXPECT_EQ(v.code, 0) << v.err;  // the good entries still vouch for every sample
  EXPECT_NE(v.err.find("evil.jsonl:1: files is missing or empty"), std::string::npos) << v.err;
  EXPECT_NE(v.err.find("evil.jsonl:2: a file needs path"), std::string::npos) << v.err;
  EXPECT_NE(v.err.find("evil.jsonl:3: index is missing or not a whole number"), std::string::npos) << v.err;
  EXPECT_NE(v.err.find("evil.jsonl:4: index 99999999999 is outside"), std::string::npos) << v.err;
  EXPECT_NE(v.err.find("evil.jsonl:5: status is missing or not a string"), std::string::npos) << v.err;
  EXPECT_NE(v.err.find("evil.jsonl:6: file path '../../../../etc/hostname' leaves the dataset"), std::string::npos) << v.err;
  EXPECT_NE(v.err.find("evil.jsonl:7: not a JSON object"), std::string::npos) << v.err;
  EXPECT_NE(v.err.find("evil.jsonl:8: files is not a list"), std::string::npos) << v.err;
  EXPECT_EQ(run("dataset finalize raw/" + name_, dir_).code, 0);
  EXPECT_EQ(run("dataset spec.toml --out raw --resume --quiet", dir_).code, 0);
  // Damaged directories are input errors, not internal ones.
  std::ofstream(ds / "spec.json", std::ios::trunc) << "{not json";
  const auto s = run("dataset verify raw/" + name_, dir_);
  EXPECT_EQ(s.code, 2);
  EXPECT_NE(s.err.find("spec.json: is not a JSON object"), std::string::npos) << s.err;
}

TEST_F(SafeDataset, RerunsNeedResumeAndAnEditedSpecIsRefusedOrRegeneratedWhereItChanged) {
  ASSERT_EQ(run("dataset spec.toml --out raw --quiet", dir_).code, 0);
  const fs::path ds = dir_ / "raw" / name_;
  const auto before = sampleHashes(ds);
  auto r = run("dataset spec.toml --out raw --quiet", dir_);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("add --resume"), std::string::npos) << r.err;
  // Comments and spacing are not changes.
  std::ofstream(dir_ / "spec.toml") << "# a comment\n" << text_ << "\n\n";
  EXPECT_EQ(run("dataset spec.toml --out raw --resume --quiet", dir_).code, 0);
  // A changed value: refused, naming the key.
  std::string edited = text_;
  edited.replace(edited.find("supersampling = 2"), 17, "supersampling = 3");
  std::ofstream(dir_ / "spec.toml", std::ios::trunc) << edited;
  r = run("dataset spec.toml --out raw --resume --quiet", dir_);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("image.supersampling (2 -> 3)"), std::string::npos) << r.err;
  EXPECT_EQ(sampleHashes(ds), before);
  // On request, the changed samples are regenerated (here all: every sample uses [image]).
  r = run("dataset spec.toml --out raw --resume --regenerate-changed", dir_);
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("16 generated, 0 skipped"), std::string::npos) << r.err;
  EXPECT_EQ(run("dataset verify raw/" + name_, dir_).code, 0);
  const auto spec_json = Json::parse(slurp(ds / "spec.json"));
  EXPECT_NE(spec_json["spec"].get<std::string>().find("supersampling = 3"), std::string::npos);
}

TEST_F(SafeDataset, AFailedRepairKeepsTheIntactGroundTruth) {
  ASSERT_EQ(run("dataset spec.toml --out raw --quiet", dir_).code, 0);
  const fs::path ds = dir_ / "raw" / name_;
  const fs::path gt = ds / "groundtruth" / "VesselTiny_0005";
  const auto gt_before = snapshot(gt);
  ASSERT_FALSE(gt_before.empty());
  // The label is damaged into a non-empty directory: the repair's rename onto it must fail.
  const fs::path label = ds / "labelsTr" / "VesselTiny_0005.nii.gz";
  fs::remove(label);
  fs::create_directories(label / "x");
  const auto r = run("dataset spec.toml --out raw --resume --quiet", dir_);
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_EQ(snapshot(gt), gt_before);
}

}  // namespace
