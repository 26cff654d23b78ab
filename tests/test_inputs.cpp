// Parameter and map files: VascuSynth's spellings accepted, bad input reported as file:line.
#include <gtest/gtest.h>

#include "grow/vascusynth/setup.hpp"
#include "config/scenario.hpp"

namespace {
const angiosynth::GrowthOptions& vsGrowth(const angiosynth::Scenario& s) {
  return dynamic_cast<const angiosynth::VascuSynthSetup&>(*s.growth).growth;
}
}  // namespace

#include <fstream>
#include <functional>

#include "core/error.hpp"
#include "test_support.hpp"

using namespace angiosynth;
namespace fs = std::filesystem;

namespace {

class Files : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("angiosynth_inputs_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    write("demand.txt", "20 20 20\n0 0 0 20 20 20\n1\n5 5 5 10 10 10\n0\n");
    write("supply.txt", "20 20 20 4\n0 0 0 20 20 20\n0.65 0.34 0.01 7\n");
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name, std::ios::binary) << text;
    return dir_ / name;
  }
  static std::string params(const std::string& eol = "\n", const std::string& sep = ": ") {
    std::string s;
    for (const char* kv : {"SUPPLY_MAP|supply.txt", "OXYGENATION_MAP|demand.txt", "RANDOM_SEED|3", "PERF_POINT|0 10 10", "PERF_PRESSURE|133000",
                           "TERM_PRESSURE|83000", "PERF_FLOW|8.33", "RHO|0.036", "GAMMA|3", "LAMBDA|2", "MU|1", "MIN_DISTANCE|1", "NUM_NODES|20",
                           "VOXEL_WIDTH|0.04", "CLOSEST_NEIGHBOURS|5"}) {
      const std::string t = kv;
      s += t.substr(0, t.find('|')) + sep + t.substr(t.find('|') + 1) + eol;
    }
    return s;
  }
  // Success if f throws an InputError starting with "<file>:<line>: " and containing `what`.
  static ::testing::AssertionResult errorAt(const fs::path& file, int line, const std::string& what, const std::function<void()>& f) {
    try {
      f();
    } catch (const InputError& e) {
      const std::string msg = e.what();
      const std::string prefix = file.string() + (line > 0 ? ":" + std::to_string(line) : "") + ": ";
      if (msg.rfind(prefix, 0) == 0 && msg.find(what) != std::string::npos) return ::testing::AssertionSuccess();
      return ::testing::AssertionFailure() << "expected '" << prefix << "…" << what << "…', got '" << msg << "'";
    }
    return ::testing::AssertionFailure() << "no error for " << what;
  }
  // `text` with its first `from` replaced by `to`.
  static std::string edited(std::string text, const std::string& from, const std::string& to) {
    const auto pos = text.find(from);
    EXPECT_NE(pos, std::string::npos) << from;
    return pos == std::string::npos ? text : text.replace(pos, from.size(), to);
  }
  fs::path dir_;
};

TEST_F(Files, VascuSynthSpellingsAreAllAccepted) {
  const auto a = readVascuSynthParameters(write("a.txt", params()));
  std::string b_text = params("\r\n", ":");
  b_text.insert(0, "\r\n");
  b_text.replace(b_text.find("RHO"), 3, "ROW");
  b_text.replace(b_text.find("MU:"), 2, "MEW");
  b_text.insert(b_text.find("GAMMA"), "\r\n\r\n");
  const auto b = readVascuSynthParameters(write("b.txt", b_text));
  EXPECT_EQ(vsGrowth(a).physics.viscosity, vsGrowth(b).physics.viscosity);
  EXPECT_EQ(vsGrowth(a).physics.cost_length_exponent, vsGrowth(b).physics.cost_length_exponent);
  EXPECT_EQ(vsGrowth(a).terminals, 20);
  // CGS: 133000 dyn/cm^2 = 13300 Pa, 8.33 cm^3/s = 8330 mm^3/s, 0.036 P = 0.0036 Pa*s, 0.04 cm = 0.4 mm.
  EXPECT_DOUBLE_EQ(vsGrowth(a).physics.perfusion_pressure, 13300);
  EXPECT_DOUBLE_EQ(vsGrowth(a).physics.perfusion_flow, 8330);
  EXPECT_DOUBLE_EQ(vsGrowth(a).physics.viscosity, 0.0036);
  EXPECT_DOUBLE_EQ(a.growth->voxelMm(), 0.4);
  EXPECT_EQ(*a.seed, 3u);
}

TEST_F(Files, VascuSynthErrorsNameFileAndLine) {
  std::string s = params();
  auto f = write("unknown.txt", s + "COLOUR: red\n");
  EXPECT_TRUE(errorAt(f, 16, "unknown key 'COLOUR'", [&] { readVascuSynthParameters(f); }));
  f = write("repeat.txt", s + "ROW: 0.04\n");
  EXPECT_TRUE(errorAt(f, 16, "RHO is given twice (first on line 8)", [&] { readVascuSynthParameters(f); }));
  std::string missing = s;
  missing.erase(missing.find("GAMMA"), missing.find('\n', missing.find("GAMMA")) - missing.find("GAMMA") + 1);
  f = write("missing.txt", missing);
  EXPECT_TRUE(errorAt(f, 0, "missing keys: GAMMA", [&] { readVascuSynthParameters(f); }));
  f = write("nan.txt", edited(s, "NUM_NODES: 20", "NUM_NODES: 2x"));
  EXPECT_TRUE(errorAt(f, 13, "'2x' is not a whole number", [&] { readVascuSynthParameters(f); }));
  f = write("range.txt", edited(s, "PERF_FLOW: 8.33", "PERF_FLOW: -1"));
  EXPECT_TRUE(errorAt(f, 7, "PERF_FLOW (cm^3/s) = -1 is out of range", [&] { readVascuSynthParameters(f); }));
  f = write("nofile.txt", edited(s, "OXYGENATION_MAP: demand.txt", "OXYGENATION_MAP: nowhere.txt"));
  EXPECT_TRUE(errorAt(f, 2, "no such file 'nowhere.txt'", [&] { readVascuSynthParameters(f); }));
}

TEST_F(Files, MapErrorsNameFileAndLine) {
  const auto ok = dynamic_cast<const VascuSynthSetup&>(*readVascuSynthParameters(write("p.txt", params())).growth).domain;
  auto sc = ok;
  sc.demand_map = write("box.txt", "20 20 20\n0 0 0 20 20 21\n1\n");
  EXPECT_TRUE(errorAt(sc.demand_map, 2, "lies outside the map", [&] { loadDomain(sc, 1ULL << 30); }));
  sc.demand_map = write("value.txt", "20 20 20\n0 0 0 20 20 20\nhigh\n");
  EXPECT_TRUE(errorAt(sc.demand_map, 3, "'high' is not a number", [&] { loadDomain(sc, 1ULL << 30); }));
  sc.demand_map = write("huge.txt", "100000 100000 100000\n0 0 0 1 1 1\n1\n");
  EXPECT_TRUE(errorAt(sc.demand_map, 1, "raise --memory-limit", [&] { loadDomain(sc, 1ULL << 30); }));
  sc = ok;
  sc.root_voxel = Vec3(30, 1, 1);
  EXPECT_TRUE(errorAt(dir_ / "p.txt", 4, "outside the 20 x 20 x 20 demand map", [&] { loadDomain(sc, 1ULL << 30); }));
  sc.root_voxel = Vec3(7, 7, 7);
  EXPECT_TRUE(errorAt(dir_ / "p.txt", 4, "zero-demand voxel", [&] { loadDomain(sc, 1ULL << 30); }));
  sc = ok;
  sc.supply_map = write("supply_bad.txt", "20 20 20 4\n0 0 0 20 20 20\n0.65 0.34 7\n");
  EXPECT_TRUE(errorAt(sc.supply_map, 3, "expected K = 4 coefficients", [&] { loadDomain(sc, 1ULL << 30); }));
  // The valid map: 5^3 zero-demand voxels, supply everywhere.
  sc = ok;
  const auto m = loadDomain(sc, 1ULL << 30);
  int zeros = 0;
  for (float d : m.demand) zeros += d == 0;
  EXPECT_EQ(zeros, 125);
}

TEST_F(Files, TomlMatchesVascuSynthAndRejectsBadUnits) {
  const std::string toml = R"(seed = 3
[domain]
demand_map = "demand.txt"
supply_map = "supply.txt"
voxel_size = "0.4 mm"
[tree]
terminals = 20
root_voxel = [0, 10, 10]
min_distance = "1 voxel"
closest_neighbours = 5
[physics]
viscosity = "3.6 mPa*s"
perfusion_pressure = "13300 Pa"
terminal_pressure = "8300 Pa"
perfusion_flow = "8330 mm3/s"
)";
  const auto t = readTomlParameters(write("p.toml", toml));
  const auto v = readVascuSynthParameters(write("p.txt", params()));
  EXPECT_DOUBLE_EQ(vsGrowth(t).physics.viscosity, vsGrowth(v).physics.viscosity);
  EXPECT_DOUBLE_EQ(vsGrowth(t).physics.perfusion_pressure, vsGrowth(v).physics.perfusion_pressure);
  EXPECT_DOUBLE_EQ(vsGrowth(t).physics.perfusion_flow, vsGrowth(v).physics.perfusion_flow);
  EXPECT_DOUBLE_EQ(vsGrowth(t).min_distance_mm, vsGrowth(v).min_distance_mm);
  auto f = write("unit.toml", edited(toml, "\"13300 Pa\"", "\"13300 bar\""));
  EXPECT_TRUE(errorAt(f, 13, "unknown unit 'bar'", [&] { readTomlParameters(f); }));
  f = write("key.toml", toml + "colour = 1\n");
  EXPECT_TRUE(errorAt(f, 16, "unknown key 'colour'", [&] { readTomlParameters(f); }));
  f = write("n.toml", edited(toml, "terminals = 20", "terminals = 0"));
  EXPECT_TRUE(errorAt(f, 7, "terminals = 0 is out of range", [&] { readTomlParameters(f); }));
  f = write("nounit.toml", edited(toml, "\"3.6 mPa*s\"", "3.6"));
  EXPECT_TRUE(errorAt(f, 12, "viscosity must be a string", [&] { readTomlParameters(f); }));
}

}  // namespace
