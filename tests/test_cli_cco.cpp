// The cco growth method end to end: parameter files, mask domains, outputs, and bad input.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "cli_run.hpp"
#include "io/volume_writers.hpp"

using namespace angiosynth;
using Json = nlohmann::json;
namespace fs = std::filesystem;

namespace {

class CliCco : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = freshTestDir("angiosynth_cli_cco_"); }
  void TearDown() override { fs::remove_all(dir_); }
  Json sample(const fs::path& out) { return Json::parse(slurp(out / "sample.json")); }
  fs::path dir_;
  const fs::path src_ = ANGIOSYNTH_SOURCE_DIR;
};

TEST_F(CliCco, DiscExampleWritesSvgAndAValidTree) {
  std::string text = slurp(src_ / "examples/cco_disc_2d.toml");
  text.replace(text.find("terminals = 4000"), 16, "terminals = 500");
  text.replace(text.find("voxel_size = \"0.1 mm\""), 21, "voxel_size = \"0.4 mm\"");
  std::ofstream(dir_ / "disc.toml") << text;
  const auto r = run("generate disc.toml --out out --quiet", dir_);
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = sample(dir_ / "out");
  EXPECT_EQ(j["parameters"]["method"], "cco");
  EXPECT_EQ(j["parameters"]["shape"], "disc");
  const auto& s = j["statistics"];
  EXPECT_EQ(s["terminals"], 500);
  EXPECT_EQ(s["intersecting_pairs"], 0);
  EXPECT_EQ(s["short_segments"], 0);
  EXPECT_EQ(s["outside_segments"], 0);
  EXPECT_EQ(s["domain_dimension"], 2);
  EXPECT_EQ(s["radius_by_bifurcation_level"][0]["segments"], 1);
  // One SVG line per segment, drawn over the disc.
  const std::string svg = slurp(dir_ / "out/tree.svg");
  std::size_t lines = 0;
  for (auto p = svg.find("<line "); p != std::string::npos; p = svg.find("<line ", p + 1)) ++lines;
  EXPECT_EQ(lines, 999u);
  EXPECT_NE(svg.find("<circle "), std::string::npos);
  EXPECT_EQ(j["files"]["svg"], "tree.svg");
  EXPECT_TRUE(fs::exists(dir_ / "out/image.nii.gz"));
}

TEST_F(CliCco, NiftiMaskDomainKeepsTerminalsInTheMask) {
  // A hollow box (a shell 6 voxels thick) as a NIfTI mask with 0.5 mm voxels.
  VolumeGrid g;
  g.dims = {32, 32, 32};
  g.spacing_mm = Vec3(0.5, 0.5, 0.5);
  std::vector<std::uint8_t> v(32 * 32 * 32, 0);
  for (int k = 1; k < 31; ++k)
    for (int j = 1; j < 31; ++j)
      for (int i = 1; i < 31; ++i)
        if (std::min({i, j, k, 31 - i, 31 - j, 31 - k}) <= 6) v[i + 32 * (j + 32 * k)] = 1;
  writeNifti(dir_ / "shell.nii.gz", VolumeView{&g, v.data(), VoxelType::UInt8, true, "shell"});
  std::ofstream(dir_ / "mask.toml") << "seed = 4\n[domain]\nshape = \"mask\"\nmask = \"shell.nii.gz\"\n"
                                       "[tree]\nmethod = \"cco\"\nterminals = 300\nroot = [8.0, 0.5, 8.0]\n"
                                       "[physics]\nperfusion_flow = \"15 mL/min\"\n"  // Karch's 5 mL/min per cm³
                                       "[image]\nformats = [\"nifti\"]\n";
  const auto r = run("generate mask.toml --out out --quiet", dir_);
  ASSERT_EQ(r.code, 0) << r.err;
  const auto s = sample(dir_ / "out")["statistics"];
  EXPECT_EQ(s["terminals"], 300);
  EXPECT_EQ(s["intersecting_pairs"], 0);
  EXPECT_EQ(s["outside_segments"], 0);
  // Every terminal (nodes.csv: id,pos_x,pos_y,pos_z,type,...) lies in a mask voxel, none in the hollow.
  std::ifstream nodes(dir_ / "out/nodes.csv");
  std::string line;
  std::getline(nodes, line);
  int terminals = 0, outside = 0;
  while (std::getline(nodes, line)) {
    std::stringstream ss(line);
    std::string id, type, x, y, z;
    std::getline(ss, id, ',');
    std::getline(ss, x, ',');
    std::getline(ss, y, ',');
    std::getline(ss, z, ',');
    std::getline(ss, type, ',');
    if (type != "terminal") continue;
    ++terminals;
    const int i = int(std::stod(x) / 0.5), j = int(std::stod(y) / 0.5), k = int(std::stod(z) / 0.5);
    if (!v[i + 32 * (j + 32 * k)]) ++outside;
  }
  EXPECT_EQ(terminals, 300);
  EXPECT_EQ(outside, 0);
}

TEST_F(CliCco, BadCcoInputNamesTheLineAndWritesNothing) {
  const std::string head = "seed = 1\n[domain]\n";
  const std::string tree = "[tree]\nmethod = \"cco\"\nterminals = 50\n";
  const auto expectError = [&](const std::string& toml, const std::string& message) {
    std::ofstream(dir_ / "bad.toml") << toml;
    const auto r = run("generate bad.toml --out out --quiet", dir_);
    EXPECT_EQ(r.code, 2) << toml;
    EXPECT_EQ(r.err.rfind("bad.toml:", 0), 0u) << r.err;
    EXPECT_NE(r.err.find(message), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir_ / "out"));
  };
  expectError(head + "shape = \"ball\"\nradius = \"10 mm\"\nvoxel_size = \"1 mm\"\n" + tree,
              "shape 'ball'; allowed: sphere, cube, disc, square (2D), mask");
  expectError(head + "demand_map = \"x.txt\"\nvoxel_size = \"1 mm\"\n" + tree, "'demand_map' in [domain] is for method vascusynth");
  expectError(head + "shape = \"cube\"\nradius = \"10 mm\"\nvoxel_size = \"1 mm\"\n" + tree, "'radius' in [domain] does not size a cube; give side");
  expectError(head + "shape = \"sphere\"\nradius = \"10 mm\"\nvoxel_size = \"1 mm\"\n" + tree + "root_offset = [0, 12, 0]\n",
              "lies outside the sphere domain");
  std::ofstream(dir_ / "m.txt") << "10 10 10\n0 0 0 9 9 9\n1\n";
  expectError(head + "shape = \"mask\"\nmask = \"m.txt\"\nvoxel_size = \"1 mm\"\n" + tree, "missing key 'root' (mm) or 'root_voxel'");
  expectError(head + "shape = \"sphere\"\nradius = \"10 mm\"\nvoxel_size = \"1 mm\"\n" + tree + "[physics]\ncost_radius_exponent = 2\n",
              "cco minimises the total volume");
}

// A tree grown in parts ([tree] parts): array tasks (--part I) and a join (--join) write the very
// sample one process writes; a rerun task keeps its part; the join refuses missing, foreign and
// damaged parts and writes nothing then.
TEST_F(CliCco, PartsGrownAsTasksAndJoinedAreTheTreeGrownInOneProcess) {
  std::string text = slurp(src_ / "examples/cco_organ_parts_3d.toml");
  text.replace(text.find("terminals = 1000000"), 19, "terminals = 3000");
  text.replace(text.find("parts = 8"), 9, "parts = 4");
  const auto voxel = text.find("voxel_size = \"");
  text.replace(voxel, text.find('"', voxel + 14) + 1 - voxel, "voxel_size = \"1 mm\"");
  std::ofstream(dir_ / "organ.toml") << text;
  const auto whole = run("generate organ.toml --out whole --quiet", dir_);
  ASSERT_EQ(whole.code, 0) << whole.err;
  for (int k = 0; k < 3; ++k) ASSERT_EQ(run("generate organ.toml --out joined --part " + std::to_string(k), dir_).code, 0);
  // The join before every task has finished: names the missing part, writes no sample.
  auto r = run("generate organ.toml --out joined --join", dir_);
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.err.find("part(s) 3 of 4"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "joined"));
  ASSERT_EQ(run("generate organ.toml --out joined --part 3", dir_).code, 0);
  r = run("generate organ.toml --out joined --part 1", dir_);
  ASSERT_EQ(r.code, 0);
  EXPECT_NE(r.err.find("kept"), std::string::npos) << r.err;
  r = run("generate organ.toml --out joined --join --quiet", dir_);
  ASSERT_EQ(r.code, 0) << r.err;
  // Every file byte for byte; sample.json but for the command line and the times.
  int compared = 0;
  for (const auto& e : fs::directory_iterator(dir_ / "whole")) {
    const auto name = e.path().filename();
    if (name == "sample.json") continue;
    EXPECT_EQ(slurp(e.path()), slurp(dir_ / "joined" / name)) << name;
    ++compared;
  }
  EXPECT_GE(compared, 4);
  Json a = sample(dir_ / "whole"), b = sample(dir_ / "joined");
  for (Json* j : {&a, &b}) {
    j->erase("command_line");
    j->erase("timing_seconds");
  }
  EXPECT_TRUE(a == b) << "sample.json differs beyond its command line and times";
  const auto& s = b["statistics"];
  EXPECT_EQ(s["terminals"], 3000);
  EXPECT_EQ(s["intersecting_pairs"], 0);
  EXPECT_EQ(s["short_segments"], 0);
  EXPECT_EQ(s["outside_segments"], 0);
  EXPECT_EQ(s["decomposition"]["parts"], 4);
  EXPECT_LE(s["decomposition"]["part_radius_scale"][1].get<double>(), 1.0);
  EXPECT_LT(s["decomposition"]["trunk_radius_share"].get<double>(), 1.0);
  // A part of another seed, and a damaged part: refused, nothing written.
  ASSERT_EQ(run("generate organ.toml --out other --part 0 --seed 2", dir_).code, 0);
  fs::copy_file(dir_ / "other.parts/part_00000.ccopart", dir_ / "joined.parts/part_00000.ccopart", fs::copy_options::overwrite_existing);
  r = run("generate organ.toml --out again --join --parts-dir joined.parts", dir_);
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.err.find("part_00000.ccopart: is part 0 of 4 grown from other parameters, seed or sample"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "again"));
  std::string bytes = slurp(dir_ / "joined.parts/part_00001.ccopart");
  bytes[bytes.size() / 2] ^= 1;
  std::ofstream(dir_ / "joined.parts/part_00001.ccopart", std::ios::binary) << bytes;
  r = run("generate organ.toml --out again --part 1 --parts-dir joined.parts", dir_);
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.err.find("part_00001.ccopart: is damaged"), std::string::npos) << r.err;
  // Bad requests, each refused before any growth.
  r = run("generate organ.toml --out x --part 4", dir_);
  EXPECT_NE(r.err.find("--part: 4 is not a part of the 4"), std::string::npos) << r.err;
  r = run("generate organ.toml --out x --part 0 --join", dir_);
  EXPECT_NE(r.err.find("--part I (one task) or --join"), std::string::npos) << r.err;
  std::ofstream(dir_ / "unseeded.toml") << text.substr(text.find("[domain]"));
  r = run("generate unseeded.toml --out x --part 0", dir_);
  EXPECT_NE(r.err.find("needs a fixed seed"), std::string::npos) << r.err;
  std::string one = text;
  one.replace(one.find("parts = 4"), 9, "parts = 1");
  std::ofstream(dir_ / "one.toml") << one;
  r = run("generate one.toml --out x", dir_);
  EXPECT_NE(r.err.find("parts = 1 is one tree grown the long way"), std::string::npos) << r.err;
  std::string big = text;
  big.replace(big.find("parts = 4"), 9, "parts = 0");
  big.replace(big.find("terminals = 3000"), 16, "terminals = 6000000");
  std::ofstream(dir_ / "big.toml") << big;
  r = run("generate big.toml --out x", dir_);
  EXPECT_NE(r.err.find("big.toml:19: terminals = 6000000 in one tree; allowed: up to 5e+06, or up to 1e+08 grown in parts"), std::string::npos)
      << r.err;
  // A trunk that cannot fit (vessels as thick as 500 mL/min makes them, in a 10 mm disc): an input error, fast.
  std::ofstream(dir_ / "tight.toml") << "seed = 1\n[domain]\nshape = \"disc\"\nradius = \"10 mm\"\nvoxel_size = \"0.1 mm\"\n"
                                        "[tree]\nmethod = \"cco\"\nterminals = 40\nparts = 8\n[physics]\nperfusion_pressure = \"99 mmHg\"\n"
                                        "perfusion_flow = \"500 mL/min\"\n";
  r = run("generate tight.toml --out x --part 0", dir_);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("tight.toml: the trunk of 8 parts"), std::string::npos) << r.err;
  r = run("generate " + (src_ / "examples/cco_disc_2d.toml").string() + " --out x --part 0 --seed 1", dir_);
  EXPECT_NE(r.err.find("grows one tree whole"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "x"));
}

}  // namespace
