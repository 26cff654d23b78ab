// Settings declared once (src/settings/schema.hpp): for every declared setting, a value in a
// parameter file and the same value given to its flag fill the same field of the same Options;
// the parameter reference prints each declaration; a value out of range is refused by both with
// the declared range.
#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>
#include <sstream>

#include "../apps/angiosynth/setting_flags.hpp"
#include "config/common_params.hpp"
#include "config/image_settings.hpp"
#include "config/mesh_settings.hpp"
#include "config/sample_settings.hpp"
#include "grow/cco/setup.hpp"
#include "config/scenario.hpp"
#include "pipeline/generate_sample.hpp"
#include "test_support.hpp"

namespace {

namespace fs = std::filesystem;
using namespace angiosynth;

// A value of the setting other than its default, as a file writes it and as a flag takes it.
struct Given {
  std::string file, flag;
};

template <class Options>
Given valueOf(const Setting<Options>& s) {
  static const Options defaults{};
  return std::visit(
      [&](auto member) -> Given {
        if constexpr (detail::isChoiceField<decltype(member)>) {
          const std::string now = member.get(defaults);
          const std::string v = s.choices.front() == now ? s.choices.back() : s.choices.front();
          return {"\"" + v + "\"", v};
        } else {
          using T = std::remove_reference_t<decltype(Options().*member)>;
          // Entries of a list: increasing, inside the range.
          const auto entries = [&](std::size_t n, bool lengths) {
            const double lo = std::max(s.range.lo, 0.0), step = std::min(s.range.hi - lo, 10.0) / double(n + 1);
            Given g{"[", ""};
            for (std::size_t k = 0; k < n; ++k) {
              const std::string v = show(lo + double(k + 1) * step);
              g.file += (k ? ", " : "") + (lengths ? "\"" + v + " mm\"" : v);
              g.flag += (k ? "," : "") + v;
            }
            g.file += "]";
            return g;
          };
          if constexpr (std::is_same_v<T, bool>)
            return {defaults.*member ? "false" : "true", ""};
          else if constexpr (std::is_same_v<T, std::optional<bool>>)
            return {"true", "1"};
          else if constexpr (std::is_same_v<T, int> || std::is_same_v<T, std::optional<int>> || std::is_same_v<T, std::int64_t>) {
            // The top of the range, or its bottom where the top is the default.
            std::int64_t v = std::int64_t(s.range.hi);
            if (defaults.*member == v) v = std::int64_t(s.range.lo);
            return {std::to_string(v), std::to_string(v)};
          } else if constexpr (std::is_same_v<T, std::string>)
            return {"\"" + s.choices.back() + "\"", s.choices.back()};
          else if constexpr (std::is_same_v<T, std::vector<std::string>>) {
            const std::string v = s.choices.empty() ? "clean" : s.choices.back();
            return {"[\"" + v + "\"]", v};
          } else if constexpr (std::is_same_v<T, std::vector<double>>) {
            // Murray's bands: two edges, and three exponents (one more) given with them.
            const bool exponents = std::string(s.key) == "murray_band_exponents";
            return entries(s.count ? s.count : exponents ? 3 : 2, s.quantity.has_value());
          } else if constexpr (std::is_same_v<T, std::optional<Vec3>>)
            return entries(3, s.quantity.has_value());
          else {
            // A number inside the range that its extra check (a bound with a hole) takes too.
            double v = s.range.lo + 0.37 * (std::min(s.range.hi, s.range.lo + 100) - s.range.lo);
            if (s.problem && !s.problem(v).empty()) v = 0.5 * (90 + s.range.hi);
            if (s.quantity) return {"\"" + show(v) + " " + internalUnit(*s.quantity) + "\"", show(v)};
            return {show(v), show(v)};
          }
        }
      },
      s.field);
}

template <class Options>
bool sameField(const Setting<Options>& s, const Options& a, const Options& b) {
  return std::visit(
      [&](auto member) {
        if constexpr (detail::isChoiceField<decltype(member)>)
          return member.get(a) == member.get(b);
        else
          return a.*member == b.*member;
      },
      s.field);
}

class Settings : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("angiosynth_settings_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  // The scenario of a parameter file whose table `table` holds `lines`.
  Scenario scenarioWith(const std::string& table, const std::string& lines) {
    std::ofstream(dir_ / "p.toml") << "[domain]\nshape = \"disc\"\nradius = \"10 mm\"\nvoxel_size = \"0.1 mm\"\n[tree]\nmethod = \"cco\"\n"
                                      "terminals = 2\n[physics]\nperfusion_flow = \"1 mL/min\"\n["
                                   << table << "]\n"
                                   << lines;
    return readTomlParameters(dir_ / "p.toml");
  }
  MeshParameters fromFile(const std::string& lines) { return scenarioWith("mesh", lines).mesh; }
  MeshParameters fromFlags(std::vector<std::string> args) {
    CLI::App app;
    MeshParameters p;
    cli::addSettingFlags(app, meshSettings(), p);
    std::reverse(args.begin(), args.end());  // CLI11 takes them last first
    app.parse(args);
    return p;
  }
  // For every setting of `settings`: the value from a file and, where it has a flag, from the
  // flag applied over the defaults as `generate` applies it over a file, fill the same field.
  // `of` picks the Options out of a scenario; `extra` adds the lines a setting needs beside it.
  template <class Options, class Of, class Extra>
  int compareFileAndFlags(const std::vector<Setting<Options>>& settings, Of&& of, Extra&& extra) {
    int compared = 0;
    for (const auto& s : settings) {
      const Given g = valueOf(s);
      std::string lines = std::string(s.key) + " = " + g.file + "\n" + extra(s);
      if (s.only_with.key) lines += std::string(s.only_with.key) + " = \"" + s.only_with.value + "\"\n";
      const Options file = of(scenarioWith(s.table, lines));
      EXPECT_FALSE(sameField(s, file, Options())) << s.key << ": the value given is the default, the comparison proves nothing";
      if (!s.flag) continue;
      CLI::App app;
      cli::SettingOverrides<Options> flags;
      flags.add(app, settings);
      std::vector<std::string> args{std::string(s.flag).substr(s.flag[0] == '!' ? 1 : 0)};
      if (!g.flag.empty()) args.push_back(g.flag);
      std::reverse(args.begin(), args.end());
      app.parse(args);
      Options from_flags;
      flags.applyTo(from_flags);
      EXPECT_TRUE(sameField(s, file, from_flags)) << s.key << " and " << s.flag << " fill different values";
      ++compared;
    }
    return compared;
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

// [image], its label, [curves], [degrade] and [output]: each key fills its field; `generate`'s
// flags (--no-image, --format, --gxl-dialect) fill the same ones over a file's values.
TEST_F(Settings, EverySampleKeyAndItsFlagFillTheSameField) {
  const auto none = [](const auto&) { return std::string(); };
  int compared = compareFileAndFlags(
      imageSettings(), [](const Scenario& sc) { return sc.image; }, none);
  compareFileAndFlags(
      labelSettings(), [](const Scenario& sc) { return sc.image.labels; }, none);
  compareFileAndFlags(
      curveSettings(), [](const Scenario& sc) { return sc.curves; }, none);
  compared += compareFileAndFlags(
      outputSettings(), [](const Scenario& sc) { return sc; }, none);
  EXPECT_EQ(compared, 3);
}

// A growth method's settings: each key of [tree] and [physics] fills its own field (a value
// other than the default it gets without the key), and the sidecar records it.
TEST_F(Settings, EveryCcoKeyFillsItsFieldAndTheSidecar) {
  const auto read = [&](const std::string& tree, const std::string& physics) {
    std::ofstream(dir_ / "p.toml") << "[domain]\nshape = \"disc\"\nradius = \"10 mm\"\nvoxel_size = \"0.1 mm\"\n[tree]\nmethod = \"cco\"\n"
                                   << tree << "[physics]\n"
                                   << physics;
    return readTomlParameters(dir_ / "p.toml");
  };
  const auto cco = [](const Scenario& sc) { return dynamic_cast<const CcoSetup&>(*sc.growth).cco; };
  const Scenario base = read("terminals = 2\n", "");
  int checked = 0;
  const auto check = [&](const auto& settings, auto&& of) {
    for (const auto& s : settings) {
      const Given g = valueOf(s);
      const std::string line = std::string(s.key) + " = " + g.file + "\n";
      const bool tree = std::string(s.table) == "tree", terminals = std::string(s.key) == "terminals";
      // A perfusion pressure this low needs a terminal pressure below it; one of Murray's band
      // settings, the other.
      const std::string key = s.key;
      const std::string partner = key == "perfusion_pressure"      ? "terminal_pressure = \"1 Pa\"\n"
                                  : key == "murray_band_edges"     ? "murray_band_exponents = [3, 2.7, 2.3]\n"
                                  : key == "murray_band_exponents" ? "murray_band_edges = [\"0.1 mm\", \"1 mm\"]\n"
                                                                   : "";
      const std::string physics = tree ? "" : line + partner;
      const Scenario sc = read((tree ? line : "") + (terminals ? "" : "terminals = 2\n"), physics);
      EXPECT_FALSE(sameField(s, of(sc), of(base))) << s.key << " = " << g.file << " left its field at the default";
      EXPECT_TRUE(sc.growth->describe().contains(s.key)) << s.key << " is missing from the sidecar";
      ++checked;
    }
  };
  check(ccoSettings(), cco);
  check(ccoPhysics(), [&](const Scenario& sc) { return cco(sc).physics; });
  check(ccoDecompositionSettings(), [&](const Scenario& sc) { return dynamic_cast<const CcoSetup&>(*sc.growth).decomposition; });
  EXPECT_EQ(checked, 18);
}

TEST_F(Settings, TheParameterReferencePrintsEachDeclaration) {
  const std::string ref = parameterReference(nullptr);
  int printed = 0;
  const auto check = [&](const auto& settings) {
    for (const auto& s : settings) {
      std::ostringstream line;
      line << "[" << s.table << "] " << s.key;
      if (*s.unit) line << " (" << s.unit << ")";
      line << ": " << s.meaning << "; default " << s.fallback << "\n";
      EXPECT_NE(ref.find(line.str()), std::string::npos) << line.str();
      ++printed;
    }
  };
  check(meshSettings());
  check(imageSettings());
  check(labelSettings());
  check(curveSettings());
  check(outputSettings());
  // Every line of the common reference is a declaration (and the seed).
  const std::string common = ref.substr(0, ref.find("\n[tree] method"));
  EXPECT_EQ(std::count(common.begin(), common.end(), '\n'), 1 + 1 + printed);
}

// The sidecar's parameters name each declared key of the tables the sample used, with its value.
TEST_F(Settings, TheSidecarRecordsEveryDeclaredSetting) {
  Scenario sc = scenarioWith("curves", "tortuosity = 1.5\n[mesh]\nvoxel_size = \"0.02 mm\"\n[image]\nlabel_policy = \"threshold\"\n");
  const auto j = describeParameters(sc);
  for (const auto& s : imageSettings()) EXPECT_TRUE(j["image"].contains(s.key)) << s.key;
  EXPECT_EQ(j["image"]["label_policy"], "threshold");
  EXPECT_EQ(j["image"]["label_threshold"], 0.5);
  EXPECT_FALSE(j["image"].contains("visible_snr"));  // a parameter of another policy
  for (const auto& s : curveSettings()) EXPECT_TRUE(j["curves"].contains(s.key)) << s.key;
  EXPECT_EQ(j["curves"]["tortuosity"], 1.5);
  for (const auto& s : meshSettings()) EXPECT_TRUE(j["mesh"].contains(s.key)) << s.key;
  EXPECT_EQ(j["mesh"]["voxel_size"]["value"], 0.02);
  EXPECT_EQ(j["mesh"]["voxel_size"]["unit"], "mm");
  EXPECT_EQ(j["mesh"]["sliver_angle"], "10 with capped ends, else 0");  // unset: the default's words
  EXPECT_EQ(j["output"]["gxl_dialect"], "gxl");
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
