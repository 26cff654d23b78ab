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

}  // namespace
