// End-to-end tests of the angiosynth command line.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <tinyxml2.h>

#include <cstdio>
#include <filesystem>
#include <functional>
#include <fstream>
#include <sstream>

#include "cli_run.hpp"
#include "core/format.hpp"
#include "grow/method.hpp"
#include "config/scenario.hpp"
#include "pipeline/generate_sample.hpp"
#include "io/graph_formats.hpp"
#include "io/mesh_writers.hpp"
#include "io/volume_formats.hpp"

using Json = nlohmann::json;
namespace fs = std::filesystem;

namespace {

class Cli : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = freshTestDir("angiosynth_cli_"); }
  void TearDown() override { fs::remove_all(dir_); }
  // VascuSynth's 1000-terminal example as p.txt (its maps found from here), listed in params.txt
  // with the output name img in names.txt: the arguments of `angiosynth vascusynth`.
  void writeVascuSynthBatch() {
    fs::copy_file(src_ / "examples/vascusynth/param_rods_1000.txt", dir_ / "p.txt");
    std::string t = slurp(dir_ / "p.txt");
    for (auto pos = t.find("../../demand_maps"); pos != std::string::npos; pos = t.find("../../demand_maps"))
      t.replace(pos, 17, (src_ / "demand_maps").string());
    std::ofstream(dir_ / "p.txt", std::ios::binary) << t;
    std::ofstream(dir_ / "params.txt") << "p.txt\n";
    std::ofstream(dir_ / "names.txt") << "img\n";
  }
  fs::path dir_;
  const fs::path src_ = ANGIOSYNTH_SOURCE_DIR;
};

TEST_F(Cli, GenerateWritesValidRoundTrippingGxlAndSidecar) {
  const auto r = run("generate '" + (src_ / "examples/vascusynth_like.toml").string() + "' --out out --quiet", dir_);
  ASSERT_EQ(r.code, 0) << r.err;
  const Json j = Json::parse(slurp(dir_ / "out/sample.json"));
  EXPECT_EQ(j["seed"], 1);
  EXPECT_EQ(j["statistics"]["terminals"], 1000);
  EXPECT_EQ(j["statistics"]["intersecting_pairs"], 0);
  EXPECT_EQ(j["files"]["gxl"], "tree.gxl");
  EXPECT_EQ(j["files"]["dot"], "tree.dot");
  EXPECT_EQ(j["parameters"]["viscosity"]["unit"], "Pa*s");
  EXPECT_LT(j["statistics"]["cost_cm"]["value"].get<double>(), 0.1719);
  ASSERT_TRUE(fs::exists(dir_ / "out/tree.dot"));
  for (const char* role : {"image", "mask", "centerline", "radius", "instances", "keypoints", "mip_x", "mip_y", "mip_z", "nodes_csv", "edges_csv",
                           "vtp", "swc", "graphml"}) {
    ASSERT_TRUE(j["files"].contains(role)) << role;
    EXPECT_TRUE(fs::exists(dir_ / "out" / j["files"][role].get<std::string>())) << role;
  }
  EXPECT_EQ(j["statistics"]["image_size"], Json::parse("[100,100,100]"));

  tinyxml2::XMLDocument doc;
  ASSERT_EQ(doc.LoadFile((dir_ / "out/tree.gxl").c_str()), tinyxml2::XML_SUCCESS);
  const auto* graph = doc.FirstChildElement("gxl")->FirstChildElement("graph");
  ASSERT_NE(graph, nullptr);
  EXPECT_STREQ(graph->Attribute("edgemode"), "directed");
  int nodes = 0, edges = 0, roots = 0, terminals = 0, kinds = 0;
  double volume = 0;
  for (const auto* n = graph->FirstChildElement("node"); n; n = n->NextSiblingElement("node")) {
    ++nodes;
    const std::string type = n->FirstChildElement("attr")->FirstChildElement("string")->GetText();
    roots += type == "root";
    terminals += type == "terminal";
  }
  for (const auto* e = graph->FirstChildElement("edge"); e; e = e->NextSiblingElement("edge")) {
    ++edges;
    double radius = 0, length = 0;
    for (const auto* a = e->FirstChildElement("attr"); a; a = a->NextSiblingElement("attr")) {
      const std::string name = a->Attribute("name");
      if (name == "kind") kinds += a->FirstChildElement("string")->GetText() == std::string("artery");
      if (!a->FirstChildElement("float")) continue;  // tree and kind are strings
      const double v = std::stod(a->FirstChildElement("float")->GetText());
      if (name == "radius") radius = v;
      if (name == "length") length = v;
    }
    volume += M_PI * radius * radius * length;
  }
  EXPECT_EQ(nodes, 2000);
  EXPECT_EQ(edges, 1999);
  EXPECT_EQ(roots, 1);
  EXPECT_EQ(terminals, 1000);
  EXPECT_EQ(kinds, 1999);  // one tree, an artery: every edge says so
  // Numbers round-trip: the volume from the GXL equals the recorded one to the last bits.
  EXPECT_NEAR(volume, j["statistics"]["total_volume"]["value"].get<double>(), 1e-12 * volume);
}

// --no-image drops the volumes, not the graph formats the file asks for.
TEST_F(Cli, NoImageStillWritesEveryGraphFormat) {
  const auto r = run("generate " + (src_ / "examples/cco_disc_2d.toml").string() + " --out g --no-image --quiet", dir_);
  ASSERT_EQ(r.code, 0) << r.err;
  for (const char* f : {"tree.gxl", "tree.dot", "nodes.csv", "edges.csv", "centerlines.vtp", "tree.swc", "tree.graphml", "keypoints.csv"})
    EXPECT_TRUE(fs::exists(dir_ / "g" / f)) << f;
  EXPECT_FALSE(fs::exists(dir_ / "g" / "image.nii.gz"));
  EXPECT_FALSE(fs::exists(dir_ / "g" / "mask.nii.gz"));
  const auto again = runPrinted("generate " + (src_ / "examples/cco_disc_2d.toml").string() + " --out g2 --no-image --quiet", dir_);
  EXPECT_EQ(again.code, 0);
  EXPECT_EQ(again.err, "");  // --quiet prints nothing
}

TEST_F(Cli, SameSeedSameBytesWhateverTheThreads) {
  const std::string params = "'" + (src_ / "examples/vascusynth/param_rods_1000.txt").string() + "'";
  ASSERT_EQ(run("generate " + params + " --out one --threads 1 --quiet", dir_).code, 0);
  ASSERT_EQ(run("generate " + params + " --out two --threads 2 --quiet", dir_).code, 0);
  EXPECT_EQ(slurp(dir_ / "one/tree.gxl"), slurp(dir_ / "two/tree.gxl"));
  EXPECT_EQ(slurp(dir_ / "one/tree.dot"), slurp(dir_ / "two/tree.dot"));
  for (const char* f : {"image.nii.gz", "mask.nii.gz", "centerline.nii.gz", "radius.nii.gz", "instances.nii.gz", "mip_z.png", "keypoints.csv",
                        "tree.graphml", "centerlines.vtp"})
    EXPECT_EQ(slurp(dir_ / "one" / f), slurp(dir_ / "two" / f)) << f;
  Json a = Json::parse(slurp(dir_ / "one/sample.json")), b = Json::parse(slurp(dir_ / "two/sample.json"));
  for (auto* j : {&a, &b}) j->erase("timing_seconds"), j->erase("command_line");
  EXPECT_EQ(a.dump(), b.dump());
  ASSERT_EQ(run("generate " + params + " --out three --seed 2 --quiet", dir_).code, 0);
  EXPECT_NE(slurp(dir_ / "one/tree.gxl"), slurp(dir_ / "three/tree.gxl"));
}

TEST_F(Cli, BadInputExitsNonZeroWithFileLineAndLeavesNoOutput) {
  std::string text = slurp(src_ / "examples/vascusynth/param_rods_1000.txt");
  text.replace(text.find("GAMMA: 3"), 8, "GAMMA: three");
  std::ofstream(dir_ / "bad.txt") << text;
  const auto r = run("generate bad.txt --out out", dir_);
  EXPECT_NE(r.code, 0);
  EXPECT_EQ(r.err.rfind("bad.txt:9: GAMMA: 'three' is not a number", 0), 0u) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "out"));
  // A growth that cannot finish (too many terminals for the space) leaves nothing either.
  text = slurp(src_ / "examples/vascusynth/param_rods_1000.txt");
  text.replace(text.find("MIN_DISTANCE: 1"), 15, "MIN_DISTANCE: 40");
  for (auto pos = text.find("../../demand_maps"); pos != std::string::npos; pos = text.find("../../demand_maps"))
    text.replace(pos, 17, (src_ / "demand_maps").string());
  std::ofstream(dir_ / "crowded.txt") << text;
  const auto c = run("generate crowded.txt --out out2 --quiet", dir_);
  EXPECT_NE(c.code, 0);
  EXPECT_NE(c.err.find("cannot lie"), std::string::npos) << c.err;
  for (const auto& e : fs::directory_iterator(dir_)) EXPECT_EQ(e.path().filename().string().find("out"), std::string::npos);
}

TEST_F(Cli, VascuSynthSubcommandWritesItsLayoutAndDialect) {
  const fs::path ex = src_ / "examples/vascusynth";
  for (const char* f : {"param_rods_1000.txt", "param_2008_crlf_200.txt", "paramList.txt", "imageNames.txt"}) fs::copy_file(ex / f, dir_ / f);
  fs::create_directories(dir_ / "../../demand_maps");
  // The parameter files name maps relative to themselves; point them at the source tree.
  for (const char* f : {"param_rods_1000.txt", "param_2008_crlf_200.txt"}) {
    std::string t = slurp(dir_ / f);
    for (auto pos = t.find("../../demand_maps"); pos != std::string::npos; pos = t.find("../../demand_maps"))
      t.replace(pos, 17, (src_ / "demand_maps").string());
    std::ofstream(dir_ / f, std::ios::binary) << t;
  }
  const auto r = run("vascusynth paramList.txt imageNames.txt 0.04 --quiet", dir_);
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string xml = slurp(dir_ / "image2/tree_structure.xml");
  EXPECT_EQ(xml.rfind("<gxl><graph id=\"image2/tree_structure.xml\" edgeids=\" true\"", 0), 0u);
  EXPECT_NE(xml.find("<attr name=\" nodeType\"><string> root node </string></attr>"), std::string::npos);
  EXPECT_NE(xml.find(" bifurication "), std::string::npos);
  EXPECT_NE(xml.find("<attr name=\" flow\"><float>8.33</float></attr>"), std::string::npos);
  EXPECT_TRUE(fs::exists(dir_ / "image1/tree_structure.xml"));
  // VascuSynth's layout, file for file: 101³ for a 100³ map at 0.04/0.04, one JPEG per slice
  // as VascuSynth writes them (the exact image as NIfTI beside them), and the DOT graph.
  EXPECT_TRUE(fs::exists(dir_ / "image1/original_image/image.nii.gz"));
  EXPECT_TRUE(fs::exists(dir_ / "image1/original_image/image000.jpg"));
  EXPECT_TRUE(fs::exists(dir_ / "image1/original_image/image100.jpg"));
  EXPECT_FALSE(fs::exists(dir_ / "image1/original_image/image101.jpg"));
  EXPECT_EQ(slurp(dir_ / "image1/original_image/image000.jpg").substr(0, 3), std::string("\xff\xd8\xff"));  // a JPEG
  EXPECT_TRUE(fs::exists(dir_ / "image1/tree.dot"));
  const Json j = Json::parse(slurp(dir_ / "image1/sample.json"));
  EXPECT_EQ(j["statistics"]["image_size"], Json::parse("[101,101,101]"));
  EXPECT_TRUE(fs::exists(dir_ / "image1/sample.json"));
}

TEST_F(Cli, OversizedImagesAreRefusedBeforeAllocating) {
  std::ofstream(dir_ / "big.toml") << slurp(src_ / "examples/vascusynth_like.toml") << "\n";
  std::string t = slurp(dir_ / "big.toml");
  const std::string rel = "\"../demand_maps/";
  t.replace(t.find(rel), rel.size(), "\"" + (src_ / "demand_maps").string() + "/");
  t.replace(t.find("[output]"), 8, "[image]\nvoxel_size = \"0.01 mm\"\n\n[output]");
  std::ofstream(dir_ / "big.toml") << t;
  const auto r = run("generate big.toml --out out --memory-limit 1 --quiet", dir_);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("an image of 4000x4000x4000 voxels needs"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("raise [image] voxel_size"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.rfind("big.toml:", 0), 0u) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "out"));
}

// A parameter file of the example with absolute map paths, written into the test directory.
std::string exampleWithProfiles(const fs::path& src, const std::string& profiles) {
  std::string t = slurp(src / "examples/vascusynth_like.toml");
  const std::string rel = "\"../demand_maps/";
  t.replace(t.find(rel), rel.size(), "\"" + (src / "demand_maps").string() + "/");
  const auto at = t.find("profiles = [");
  t.replace(at, t.find('\n', at) - at, "profiles = [" + profiles + "]");
  return t;
}

TEST_F(Cli, ProfilesGiveOneDegradedImageEachWithWarpedLabelsAndTheSameBytesForAnyThreads) {
  std::ofstream(dir_ / "warpy.toml") << "[[effect]]\ntype = \"warp\"\nspacing = \"10 mm\"\nmax_displacement = \"2 mm\"\n"
                                        "[[effect]]\ntype = \"rician\"\nsigma = 12\n";
  std::ofstream(dir_ / "p.toml") << exampleWithProfiles(src_, "\"cta\", \"warpy.toml\"");
  ASSERT_EQ(run("generate p.toml --out one --threads 1 --quiet", dir_).code, 0);
  ASSERT_EQ(run("generate p.toml --out two --threads 2 --quiet", dir_).code, 0);
  for (const char* f : {"image_cta.nii.gz", "image_warpy.nii.gz", "mask_warpy.nii.gz", "centerline_warpy.nii.gz", "radius_warpy.nii.gz",
                        "instances_warpy.nii.gz", "tree_warpy.gxl", "warp_warpy.json", "mip_z_cta.png"}) {
    ASSERT_TRUE(fs::exists(dir_ / "one" / f)) << f;
    EXPECT_EQ(slurp(dir_ / "one" / f), slurp(dir_ / "two" / f)) << f;
  }
  const Json j = Json::parse(slurp(dir_ / "one/sample.json"));
  EXPECT_EQ(j["files"]["image_cta"], "image_cta.nii.gz");
  EXPECT_EQ(j["degradation"]["cta"]["dtype"], "int16");
  const auto& cta_effects = j["degradation"]["cta"]["effects"];
  ASSERT_EQ(cta_effects.size(), 6u);
  ASSERT_EQ(cta_effects[5]["type"], "gaussian");
  const double sigma = cta_effects[5]["parameters"]["sigma"];
  EXPECT_TRUE(sigma >= 10 && sigma <= 25) << sigma;
  EXPECT_GT(j["degradation"]["warpy"]["effects"][0]["min_jacobian_determinant"].get<double>(), 0);
  // The clean outputs are untouched by the profiles.
  ASSERT_EQ(run("generate p.toml --out plain --no-profiles --quiet", dir_).code, 0);
  EXPECT_EQ(slurp(dir_ / "one/mask.nii.gz"), slurp(dir_ / "plain/mask.nii.gz"));
  EXPECT_FALSE(fs::exists(dir_ / "plain/image_cta.nii.gz"));
}

// VascuSynth's own rules, by switch for its files and by key for ours: no minimum length in radii,
// no relaxation, overlapping vessels allowed (VascuSynth's 1000-terminal trees overlap in dozens
// of pairs; this program's own rules leave none). Each command states its grid: VascuSynth's of
// map-voxel corners (101^3 for a 100^3 map) and generate's of voxel centres (100^3); the sidecar
// lists only the formats written.
TEST_F(Cli, VascuSynthRulesReproduceItsConstraintsAndEachCommandStatesItsGrid) {
  writeVascuSynthBatch();
  const auto ok = run("vascusynth params.txt names.txt 0.04 --vascusynth-rules", dir_);
  ASSERT_EQ(ok.code, 0) << ok.err;
  EXPECT_NE(ok.err.find("image 101 x 101 x 101 voxels centred on the map voxels' corners"), std::string::npos) << ok.err;
  const Json j = Json::parse(slurp(dir_ / "img/sample.json"));
  EXPECT_EQ(j["parameters"]["rules"], "vascusynth");
  EXPECT_EQ(j["parameters"]["min_length_ratio"], 0.0);
  EXPECT_EQ(j["parameters"]["relax_sweeps"], 0);
  EXPECT_EQ(j["parameters"]["avoid_intersections"], false);
  EXPECT_EQ(j["statistics"]["relaxed_bifurcations"], 0);
  EXPECT_GT(j["statistics"]["intersecting_pairs"].get<int>(), 10);
  EXPECT_EQ(j["units"]["image_grid"]["voxels"], Json::array({101, 101, 101}));
  EXPECT_EQ(j["parameters"]["image"]["formats"], Json::array({"nifti"}));
  for (const auto& [role, file] : j["files"].items()) {
    std::string name = file.get<std::string>();
    if (const auto pattern = name.find("%03d"); pattern != std::string::npos) name.replace(pattern, 4, "000");  // the first slice
    EXPECT_TRUE(fs::exists(dir_ / "img" / name)) << role;
  }
  // The same map through generate: this program's rules, its grid of voxel centres.
  const auto own = run("generate p.txt --out own --no-profiles", dir_);
  ASSERT_EQ(own.code, 0) << own.err;
  EXPECT_NE(own.err.find("0 intersecting pairs"), std::string::npos) << own.err;
  EXPECT_NE(own.err.find("image 100 x 100 x 100 voxels of 0.4 mm, centres (i + 1/2) voxels"), std::string::npos) << own.err;
  // The key in a .toml file, which may not also set what it fixes; the switch is for VascuSynth files.
  std::string toml = slurp(src_ / "examples/vascusynth_like.toml");
  toml.replace(toml.find("\"../demand_maps/"), 16, "\"" + (src_ / "demand_maps").string() + "/");
  const auto at = toml.find("[tree]\n") + 7;
  std::ofstream(dir_ / "rules.toml") << toml.substr(0, at) << "rules = \"vascusynth\"\n" << toml.substr(at);
  const auto keyed = run("generate rules.toml --out keyed --no-image --quiet", dir_);
  ASSERT_EQ(keyed.code, 0) << keyed.err;
  EXPECT_EQ(Json::parse(slurp(dir_ / "keyed/sample.json"))["parameters"]["relax_sweeps"], 0);
  std::ofstream(dir_ / "both.toml") << toml.substr(0, at) << "rules = \"vascusynth\"\nrelax_sweeps = 2\n" << toml.substr(at);
  const auto both = run("generate both.toml --out both --no-image --quiet", dir_);
  EXPECT_EQ(both.code, 2);
  EXPECT_NE(both.err.find("both.toml:"), std::string::npos) << both.err;
  EXPECT_NE(both.err.find("relax_sweeps is set by rules = \"vascusynth\""), std::string::npos) << both.err;
  EXPECT_EQ(run("generate rules.toml --out x --vascusynth-rules --quiet", dir_).code, 2);
}

TEST_F(Cli, VascuSynthNoiseFilesGiveNoiseImagesAndMisspellingsStopEverything) {
  writeVascuSynthBatch();
  std::ofstream(dir_ / "noise.txt") << "GAUSSIAN: 0 20\nSHADOW: 2\n";
  std::ofstream(dir_ / "typo.txt") << "GAUSSIAN: 0 20\nSALTPEPER 255 0.05 0 0.05\n";
  const auto bad = run("vascusynth params.txt names.txt 0.04 noise.txt typo.txt", dir_);
  EXPECT_EQ(bad.code, 2);
  EXPECT_EQ(bad.err.rfind("typo.txt:2: unknown noise directive 'SALTPEPER'", 0), 0u) << bad.err;
  EXPECT_FALSE(fs::exists(dir_ / "img"));
  // Noise folders counted from 0 in argument order, as VascuSynth's; --slices png: lossless slices.
  const auto ok = run("vascusynth params.txt names.txt 0.04 noise.txt noise.txt --slices png --quiet", dir_);
  ASSERT_EQ(ok.code, 0) << ok.err;
  for (const char* sub : {"noise_image_0", "noise_image_1"}) {
    EXPECT_TRUE(fs::exists(dir_ / "img" / sub / "image.nii.gz")) << sub;
    EXPECT_TRUE(fs::exists(dir_ / "img" / sub / "image000.png")) << sub;
    EXPECT_TRUE(fs::exists(dir_ / "img" / sub / "image100.png")) << sub;
  }
  EXPECT_FALSE(fs::exists(dir_ / "img" / "noise_image_2"));
  // Two copies of one noise file are two independent draws.
  EXPECT_NE(slurp(dir_ / "img/noise_image_0/image.nii.gz"), slurp(dir_ / "img/noise_image_1/image.nii.gz"));
  const Json j = Json::parse(slurp(dir_ / "img/sample.json"));
  EXPECT_EQ(j["degradation"]["noise_image_0"]["effects"][1]["shadows"].size(), 2u);
}

// `init METHOD FILE` writes a template of every method that the reader takes and that grows;
// every key is listed, in its own table; each `key = value` line, uncommented alone, gives a file
// whose sample's inputs pass every check before growth and, but for tables whose presence turns
// a stage on ([curves], [mesh]), the same resolved parameters: the value is the default. It
// never replaces a file.
TEST_F(Cli, InitTemplatesRunAsTheyAreAndEveryCommentedKeyUncommentedAlone) {
  for (const auto* m : angiosynth::growthMethods()) {
    const std::string name = m->name, file = name + ".toml";
    const auto r = run("init " + name + " " + file, dir_);
    ASSERT_EQ(r.code, 0) << name << ": " << r.err;
    const angiosynth::Scenario sc = angiosynth::readTomlParameters(dir_ / file);
    EXPECT_EQ(std::string(sc.growth->method()), name);
    // Compared at 12 significant digits: "0.05 voxel" of 0.4 mm is 0.020000000000000004 mm
    // where the default is computed as 0.02.
    const auto rounded = [](const angiosynth::Scenario& s) {
      std::function<void(Json&)> round = [&](Json& j) {
        if (j.is_number_float()) j = std::stod(angiosynth::show(j.get<double>(), 12));
        if (j.is_structured())
          for (auto& v : j) round(v);
      };
      Json j = Json::parse(angiosynth::describeParameters(s).dump());
      round(j);
      return j.dump();
    };
    const std::string resolved = rounded(sc);
    const std::string text = slurp(dir_ / file);
    // Every key of the method is listed: set by the example, a line to uncomment, or described.
    std::size_t listed = 0;
    for (const auto& p : m->params) {
      const std::string key = p.key, dotted = std::string(p.table) + "." + key;
      listed += text.find("\n" + key + " = ") != std::string::npos || text.find("# " + key + " = ") != std::string::npos ||
                text.find("#   " + key + ": ") != std::string::npos || text.find("# " + dotted + " = ") != std::string::npos ||
                text.find("#   " + dotted + ": ") != std::string::npos;
    }
    EXPECT_EQ(listed, m->params.size()) << name;
    std::istringstream lines(text);
    int uncommentable = 0;
    for (std::string line; std::getline(lines, line);) {
      const auto eq = line.find(" = ");
      if (line.rfind("# ", 0) != 0 || line.rfind("#  ", 0) == 0 || eq == std::string::npos) continue;
      const std::string key = line.substr(2, eq - 2);
      if (key.find_first_not_of("abcdefghijklmnopqrstuvwxyz_.0123456789") != std::string::npos) continue;  // prose
      ++uncommentable;
      std::string trial = text;
      trial.replace(trial.find(line), line.size(), line.substr(2));
      std::ofstream(dir_ / ("uncommented_" + file)) << trial;
      try {
        const angiosynth::Scenario u = angiosynth::readTomlParameters(dir_ / ("uncommented_" + file));
        angiosynth::checkSampleInputs(u, 8ull << 30);
        if (key.rfind("curves.", 0) != 0 && key.rfind("mesh.", 0) != 0) { EXPECT_TRUE(rounded(u) == resolved) << name << ": " << line; }
      } catch (const std::exception& e) { ADD_FAILURE() << name << ": uncommenting '" << line << "': " << e.what(); }
    }
    EXPECT_GT(uncommentable, 20) << name;
    const auto again = run("init " + name + " " + file, dir_);
    EXPECT_EQ(again.code, 2);
    EXPECT_NE(again.err.find("exists"), std::string::npos) << again.err;
    EXPECT_EQ(slurp(dir_ / file), text);
  }
  // The cco template grows: a run of the file as written.
  ASSERT_EQ(run("generate cco.toml --out grown --no-image --quiet", dir_).code, 0);
  EXPECT_TRUE(fs::exists(dir_ / "grown/tree.gxl"));
  const auto p = runPrinted("params colonisation", dir_);
  ASSERT_EQ(p.code, 0);
  for (const char* key : {"[image] supersampling", "[curves] tortuosity", "[stage] co2_distance", "seed"})
    EXPECT_NE(p.err.find(key), std::string::npos) << key;
  EXPECT_EQ(runPrinted("params nosuch", dir_).code, 2);
}

TEST_F(Cli, HelpAndVersion) {
  EXPECT_EQ(run("--version", dir_).code, 0);
  EXPECT_EQ(run("generate --help", dir_).code, 0);
  EXPECT_EQ(run("vascusynth --help", dir_).code, 0);
  EXPECT_NE(run("generate", dir_).code, 0);
}

}  // namespace

TEST_F(Cli, EveryRegisteredFormatIsListedByParamsAndTakenByFileAndFlag) {
  // The format registries are the only lists: the parameter reference, the readers and the
  // flags read them (the reference once left out 3mf, which the reader took).
  const auto reference = runPrinted("params", dir_);
  ASSERT_EQ(reference.code, 0) << reference.err;
  for (const auto& f : angiosynth::volumeFormats()) EXPECT_NE(reference.err.find(std::string(f.name) + " ("), std::string::npos) << f.name;
  for (const auto& f : angiosynth::graphFormats()) EXPECT_NE(reference.err.find(std::string(f.name) + " ("), std::string::npos) << f.name;
  for (const auto& f : angiosynth::meshFormats()) EXPECT_NE(reference.err.find(std::string(f.name) + " ("), std::string::npos) << f.name;
  const auto help = runPrinted("generate --help", dir_), mesh_help = runPrinted("mesh --help", dir_);
  EXPECT_NE(help.err.find("mha (MetaImage"), std::string::npos) << help.err;
  EXPECT_NE(mesh_help.err.find("3mf (3MF"), std::string::npos) << mesh_help.err;
  // The description names no list of its own that could drift from the registry's.
  EXPECT_EQ(mesh_help.err.find("(STL, OBJ, PLY, OFF, VTP)"), std::string::npos) << mesh_help.err;
  // Options a command does not use are not offered: only the commands reading VascuSynth files
  // take their length unit.
  for (const char* command : {"score", "mesh", "dataset"}) {
    const auto h = runPrinted(std::string(command) + " --help", dir_);
    EXPECT_EQ(h.err.find("--vascusynth-unit"), std::string::npos) << command;
    EXPECT_EQ(h.err.find("refuse maps"), std::string::npos) << command;
  }
  EXPECT_NE(runPrinted("vascusynth --help", dir_).err.find("--vascusynth-unit"), std::string::npos);
  // A format the registry lacks is refused by the file reader, naming what is allowed.
  std::ifstream in(src_ / "examples/cco_disc_2d.toml");
  std::stringstream text;
  text << in.rdbuf();
  std::string p = text.str();
  p.replace(p.find("formats = [\"nifti\", \"png\"]"), 26, "formats = [\"mha\", \"dicom\"]");
  std::ofstream(dir_ / "p.toml") << p;
  const auto refused = run("generate p.toml --out o", dir_);
  EXPECT_EQ(refused.code, 2) << refused.err;
  EXPECT_NE(refused.err.find("dicom"), std::string::npos) << refused.err;
  EXPECT_NE(refused.err.find("mha"), std::string::npos) << refused.err;
}
