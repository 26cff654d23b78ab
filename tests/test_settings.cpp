// Settings declared once (src/settings/schema.hpp): for every declared [mesh] setting, a value in
// a parameter file and the same value given to its flag fill the same field of the same Options;
// the parameter reference prints each declaration; a value out of range is refused by both with
// the declared range.
#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>
#include <sstream>

#include "../apps/angiosynth/setting_flags.hpp"
#include "config/common_params.hpp"
#include "config/mesh_settings.hpp"
#include "config/scenario.hpp"
#include "test_support.hpp"

namespace {

namespace fs = std::filesystem;
using namespace angiosynth;

// A value of the setting other than its default, as a file writes it and as a flag takes it.
struct Given {
  std::string file, flag;
};

Given valueOf(const Setting<MeshParameters>& s) {
  return std::visit(
      [&](auto member) -> Given {
        using T = std::remove_reference_t<decltype(MeshParameters().*member)>;
        if constexpr (std::is_same_v<T, bool>) return {"true", ""};
        else if constexpr (std::is_same_v<T, std::optional<bool>>) return {"true", "1"};
        else if constexpr (std::is_same_v<T, int>) return {std::to_string(int(s.range.hi)), std::to_string(int(s.range.hi))};
        else if constexpr (std::is_same_v<T, std::string>) return {"\"" + s.choices.back() + "\"", s.choices.back()};
        else if constexpr (std::is_same_v<T, std::vector<std::string>>) return {"[\"" + s.choices.back() + "\"]", s.choices.back()};
        else if constexpr (std::is_same_v<T, std::vector<double>>) return {"[1, 2, 3, 4, 5, 6]", "1,2,3,4,5,6"};
        else {
          // A number inside the range that its extra check (a bound with a hole) takes too.
          double v = s.range.lo + 0.37 * (std::min(s.range.hi, s.range.lo + 100) - s.range.lo);
          if (s.problem && !s.problem(v).empty()) v = 0.5 * (90 + s.range.hi);
          if (s.length) return {"\"" + show(v) + " mm\"", show(v)};
          return {show(v), show(v)};
        }
      },
      s.field);
}

bool sameField(const Setting<MeshParameters>& s, const MeshParameters& a, const MeshParameters& b) {
  return std::visit([&](auto member) { return a.*member == b.*member; }, s.field);
}

class Settings : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("angiosynth_settings_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  // The scenario of a parameter file whose [mesh] table holds `lines`.
  MeshParameters fromFile(const std::string& lines) {
    std::ofstream(dir_ / "p.toml") << "[domain]\nshape = \"disc\"\nradius = \"10 mm\"\nvoxel_size = \"0.1 mm\"\n[tree]\nmethod = \"cco\"\n"
                                      "terminals = 2\n[physics]\nperfusion_flow = \"1 mL/min\"\n[mesh]\n"
                                   << lines;
    return readTomlParameters(dir_ / "p.toml").mesh;
  }
  MeshParameters fromFlags(std::vector<std::string> args) {
    CLI::App app;
    MeshParameters p;
    cli::addSettingFlags(app, meshSettings(), p);
    std::reverse(args.begin(), args.end());  // CLI11 takes them last first
    app.parse(args);
    return p;
  }
  fs::path dir_;
};

TEST_F(Settings, EveryMeshKeyAndItsFlagFillTheSameField) {
  int compared = 0;
  for (const auto& s : meshSettings()) {
    const Given g = valueOf(s);
    // A flow extension needs open ends, in a file and on the command line alike.
    const bool needs_open = std::string(s.key) == "flow_extension";
    const MeshParameters file = fromFile(std::string(s.key) + " = " + g.file + "\n" + (needs_open ? "ends = \"open\"\n" : ""));
    EXPECT_FALSE(sameField(s, file, MeshParameters())) << s.key << ": the value given is the default, the comparison proves nothing";
    if (!s.flag) continue;
    std::vector<std::string> args{s.flag};
    if (!g.flag.empty()) args.push_back(g.flag);
    if (needs_open) args.insert(args.end(), {"--ends", "open"});
    const MeshParameters flags = fromFlags(args);
    EXPECT_TRUE(sameField(s, file, flags)) << s.key << " and " << s.flag << " fill different values";
    ++compared;
  }
  EXPECT_GE(compared, 19);
}

TEST_F(Settings, TheParameterReferencePrintsEachDeclaration) {
  const std::string ref = parameterReference(nullptr);
  for (const auto& s : meshSettings()) {
    std::ostringstream line;
    line << "[" << s.table << "] " << s.key;
    if (*s.unit) line << " (" << s.unit << ")";
    line << ": " << s.meaning << "; default " << s.fallback << "\n";
    EXPECT_NE(ref.find(line.str()), std::string::npos) << line.str();
  }
}

TEST_F(Settings, AValueOutOfRangeIsRefusedByFileAndFlagWithTheDeclaredRange) {
  try {
    fromFile("sliver_angle = 45\n");
    ADD_FAILURE() << "sliver_angle = 45 was taken";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("p.toml:11: sliver_angle = 45 is out of range; allowed: [0, 30] degrees"), std::string::npos) << e.what();
  }
  try {
    fromFlags({"--sliver-angle", "45"});
    ADD_FAILURE() << "--sliver-angle 45 was taken";
  } catch (const CLI::ValidationError& e) {
    EXPECT_NE(std::string(e.what()).find("45 is out of range; allowed: [0, 30] degrees"), std::string::npos) << e.what();
  }
  // A rule between settings, from the file: the line of the first of its keys given (ends).
  try {
    fromFile("wall_ratio = 0.2\nends = \"capped\"\n");
    ADD_FAILURE() << "a capped hollow wall was taken";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("p.toml:12: a hollow wall keeps its ends open"), std::string::npos) << e.what();
  }
}

}  // namespace
