// The shipped examples' outputs, byte for byte, against the SHA-256 recorded in
// tests/data/example_outputs.sha256: a refactoring must
// not change one byte of what the examples write. JSON sidecars are compared without what
// depends on the run rather than the data (time, command line, absolute paths).
// ANGIOSYNTH_RECORD_EXAMPLE_HASHES=1 rewrites the record instead of checking it.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstdlib>
#include <map>

#include "cli_run.hpp"
#include "dataset/manifest.hpp"

namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

// Drops what differs between runs of the same data; paths keep their file name only.
void normalise(Json& j) {
  if (j.is_object()) {
    for (const char* k : {"command_line", "timing_seconds", "parameter_file", "spec_file"}) j.erase(k);
    for (auto& [k, v] : j.items()) {
      if (v.is_string() && (k == "demand_map" || k == "supply_map" || k == "mask" || k == "source" || k == "file"))
        v = fs::path(v.get<std::string>()).filename().string();
      else
        normalise(v);
    }
  } else if (j.is_array()) {
    for (auto& v : j) normalise(v);
  }
}

std::string digest(const fs::path& f) {
  if (f.extension() != ".json") return angiosynth::sha256File(f);
  Json j = Json::parse(slurp(f));
  normalise(j);
  return angiosynth::sha256Text(j.dump());
}

void hashTree(const fs::path& root, const std::string& label, std::map<std::string, std::string>& out) {
  for (const auto& e : fs::recursive_directory_iterator(root)) {
    if (!e.is_regular_file()) continue;
    const std::string rel = fs::relative(e.path(), root).generic_string();
    // Dataset bookkeeping (times, machines) is not sample data.
    const std::string name = e.path().filename().string();
    if (rel.find("manifest") != std::string::npos || name == "provenance.json" || name == "spec.json" || name == "stderr.txt") continue;
    out[label + "/" + rel] = digest(e.path());
  }
}

TEST(ExampleOutputs, EveryFileTheShippedExamplesWriteIsByteIdenticalToTheRecord) {
  const fs::path src = ANGIOSYNTH_SOURCE_DIR, dir = freshTestDir("angiosynth_examples_");
  const auto ex = [&](const char* f) {
    std::string quoted(1, '\'');  // appended: GCC 12 warns falsely (-Wrestrict) on "'" + string
    quoted += (src / "examples" / f).string();
    quoted += '\'';
    return quoted;
  };
  ASSERT_EQ(run("generate " + ex("vascusynth_like.toml") + " --out vascusynth_like --quiet", dir).code, 0);
  ASSERT_EQ(run("generate " + ex("cco_sphere_3d.toml") + " --out cco_sphere_3d --quiet", dir).code, 0);
  ASSERT_EQ(run("generate " + ex("cco_sphere_curved_3d.toml") + " --out cco_sphere_curved_3d --quiet", dir).code, 0);
  ASSERT_EQ(run("generate " + ex("cco_disc_2d.toml") + " --out cco_disc_2d --quiet", dir).code, 0);
  ASSERT_EQ(run("generate " + ex("cco_two_inlets_2d.toml") + " --out cco_two_inlets_2d --quiet", dir).code, 0);
  ASSERT_EQ(run("generate " + ex("cco_artery_vein_3d.toml") + " --out cco_artery_vein_3d --quiet", dir).code, 0);
  ASSERT_EQ(run("generate " + ex("dcco_scale_specific_2d.toml") + " --out dcco_scale_specific_2d --quiet", dir).code, 0);
  ASSERT_EQ(run("generate " + ex("dcco_outlet_half_2d.toml") + " --out dcco_outlet_half_2d --quiet", dir).code, 0);
  ASSERT_EQ(run("generate " + ex("dcco_junctions_2d.toml") + " --out dcco_junctions_2d --quiet", dir).code, 0);
  ASSERT_EQ(run("generate " + ex("colonisation_fig5_2d.toml") + " --out colonisation_fig5_2d --quiet", dir).code, 0);
  ASSERT_EQ(run("generate " + ex("lsystem_lzh_2d.toml") + " --out lsystem_lzh_2d --quiet", dir).code, 0);
  ASSERT_EQ(run("generate " + ex("lsystem_grammar_2d.toml") + " --out lsystem_grammar_2d --quiet", dir).code, 0);
  ASSERT_EQ(run("dataset " + ex("dataset_small.toml") + " --out dataset_small --quiet", dir).code, 0);
  fs::copy(src / "examples/vascusynth", dir / "vascusynth", fs::copy_options::recursive);
  for (const char* f : {"param_rods_1000.txt", "param_2008_crlf_200.txt"})
    std::ofstream(dir / "vascusynth" / f, std::ios::binary) << selfContained(src / "examples/vascusynth" / f);
  ASSERT_EQ(run("vascusynth paramList.txt imageNames.txt 0.04 --quiet", dir / "vascusynth").code, 0);
  std::map<std::string, std::string> now;
  for (const char* out : {"vascusynth_like", "cco_sphere_3d", "cco_sphere_curved_3d", "cco_disc_2d", "cco_two_inlets_2d", "cco_artery_vein_3d",
                          "dcco_scale_specific_2d", "dcco_outlet_half_2d", "dcco_junctions_2d", "colonisation_fig5_2d", "lsystem_lzh_2d",
                          "lsystem_grammar_2d", "dataset_small"})
    hashTree(dir / out, out, now);
  for (const char* out : {"image1", "image2"}) hashTree(dir / "vascusynth" / out, std::string("vascusynth/") + out, now);
  const fs::path record = src / "tests/data/example_outputs.sha256";
  // Another compiler rounds some floating-point steps differently and grows other (valid) trees;
  // the record holds for the compiler that made it.
  const std::string compiler = std::string("# compiler: ") + __VERSION__;
  if (const char* r = std::getenv("ANGIOSYNTH_RECORD_EXAMPLE_HASHES"); r && std::string(r) == "1") {
    std::ofstream o(record);
    o << compiler << "\n";
    for (const auto& [k, v] : now) o << v << "  " << k << "\n";
    GTEST_SKIP() << "recorded " << now.size() << " hashes in " << record;
  }
  std::istringstream in(slurp(record));
  std::string first;
  std::getline(in, first);
  if (first != compiler) GTEST_SKIP() << "the record is of another compiler (" << first << ")";
  std::map<std::string, std::string> want;
  for (std::string h, k; in >> h >> k;) want[k] = h;
  ASSERT_GT(want.size(), 100u) << "no record at " << record;
  for (const auto& [k, v] : want) {
    const auto it = now.find(k);
    if (it == now.end())
      ADD_FAILURE() << "not written any more: " << k;
    else
      EXPECT_EQ(it->second, v) << "changed: " << k;
  }
  for (const auto& [k, v] : now) EXPECT_TRUE(want.count(k)) << "new file: " << k;
  fs::remove_all(dir);
}

}  // namespace
