// Growth methods as plug-ins: the registry, the declarations that drive reader, defaults and
// reference, and the docs generated from them.
#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>

#include "core/error.hpp"
#include "core/units.hpp"
#include "grow/cco/setup.hpp"
#include "grow/common/method_tables.hpp"
#include "grow/method.hpp"
#include "config/scenario.hpp"
#include "test_support.hpp"

namespace angiosynth {
namespace {

namespace fs = std::filesystem;

TEST(Methods, TheDocsListEveryMethodAsTheCodeDeclaresIt) {
  std::ifstream in(test::sourceDir() / "docs/methods.md");
  const std::string page((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(page.find(methodReference()), std::string::npos) << "run bash scripts/docs.sh: docs/methods.md lists the methods";
}

TEST(Methods, EveryDeclaredDefaultIsReadableInItsUnitAndDeclaredOnce) {
  for (const auto* m : growthMethods()) {
    EXPECT_EQ(findGrowthMethod(m->name), m);
    for (std::size_t i = 0; i < m->params.size(); ++i) {
      const auto& p = m->params[i];
      for (std::size_t j = 0; j < i; ++j)
        EXPECT_FALSE(std::string(p.table) == m->params[j].table && std::string(p.key) == m->params[j].key)
            << m->name << " declares [" << p.table << "] " << p.key << " twice";
      if (!p.fallback || p.fallback[0] == '[') continue;  // "[physics] ...": another key's value
      const std::string unit = p.unit;
      const auto dim = unit == "Pa"       ? Dimension::Pressure
                       : unit == "Pa*s"   ? Dimension::Viscosity
                       : unit == "mm^3/s" ? Dimension::Flow
                                          : Dimension::Length;
      if (unit == "Pa" || unit == "Pa*s" || unit == "mm^3/s" || (unit == "mm" && std::string(p.fallback) != "none")) {
        EXPECT_NO_THROW(parseQuantity(p.fallback, dim, 1.0)) << m->name << " " << p.key << " = " << p.fallback;
      }
    }
  }
  EXPECT_EQ(findGrowthMethod("lsystem-not-yet"), nullptr);
}

class MethodFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("angiosynth_methods_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path write(const std::string& text) {
    const auto f = dir_ / "p.toml";
    std::ofstream(f) << text;
    return f;
  }
  fs::path dir_;
};

// The defaults a CCO file leaves out are the declared ones, parsed from the declarations.
TEST_F(MethodFiles, OmittedKeysTakeTheDeclaredDefaults) {
  const auto sc =
      readTomlParameters(write("[domain]\nshape = \"sphere\"\nradius = \"10 mm\"\nvoxel_size = \"0.5 mm\"\n"
                               "[tree]\nmethod = \"cco\"\nterminals = 100\n"));
  const auto& c = dynamic_cast<const CcoSetup&>(*sc.growth).cco;
  const auto declared = [&](const char* table, const char* key, Dimension dim) {
    return parseQuantity(findParam(kCcoMethod, table, key)->fallback, dim, 0.5);
  };
  EXPECT_EQ(c.physics.viscosity, declared("physics", "viscosity", Dimension::Viscosity));
  EXPECT_EQ(c.physics.perfusion_pressure, declared("physics", "perfusion_pressure", Dimension::Pressure));
  EXPECT_EQ(c.physics.terminal_pressure, declared("physics", "terminal_pressure", Dimension::Pressure));
  EXPECT_EQ(c.physics.perfusion_flow, declared("physics", "perfusion_flow", Dimension::Flow));
  EXPECT_EQ(c.closest_neighbours, std::stoi(findParam(kCcoMethod, "tree", "closest_neighbours")->fallback));
  EXPECT_EQ(c.max_neighbours, c.closest_neighbours);  // the declared default: closest_neighbours
  EXPECT_EQ(c.relaxation, std::stod(findParam(kCcoMethod, "tree", "relaxation")->fallback));
  EXPECT_EQ(std::string(sc.growth->method()), "cco");
}

// ν stays unless max_closest_neighbours asks for more, whatever ν is.
TEST_F(MethodFiles, NuDoublesOnlyUpToAMaximumTheFileGives) {
  const std::string head =
      "[domain]\nshape = \"sphere\"\nradius = \"10 mm\"\nvoxel_size = \"0.5 mm\"\n"
      "[tree]\nmethod = \"cco\"\nterminals = 100\nclosest_neighbours = 10\n";
  const auto max_nu = [&](const std::string& extra) {
    const auto sc = readTomlParameters(write(head + extra));
    return dynamic_cast<const CcoSetup&>(*sc.growth).cco.max_neighbours;
  };
  EXPECT_EQ(max_nu(""), 10);
  EXPECT_EQ(max_nu("max_closest_neighbours = 40\n"), 40);
  EXPECT_EQ(max_nu("max_closest_neighbours = 10\n"), 10);
}

// A key no method declares is refused with the method's own keys; a key of another method
// names that method; an unknown method lists the registered ones.
TEST_F(MethodFiles, KeysAreCheckedAgainstTheDeclarations) {
  const std::string head = "[domain]\nshape = \"sphere\"\nradius = \"10 mm\"\nvoxel_size = \"0.5 mm\"\n";
  const auto message = [&](const std::string& text) {
    try {
      readTomlParameters(write(text));
    } catch (const InputError& e) { return std::string(e.what()); }
    return std::string("no error");
  };
  std::string m = message(head + "[tree]\nmethod = \"cco\"\nterminals = 100\nbranching = 3\n");
  EXPECT_NE(m.find("p.toml:8: unknown key 'branching' in [tree] of method cco; allowed: bifurcation, closest_neighbours,"), std::string::npos) << m;
  m = message(head + "[tree]\nmethod = \"cco\"\nterminals = 100\nmin_distance = \"1 mm\"\n");
  EXPECT_NE(m.find("p.toml:8: 'min_distance' in [tree] is for method vascusynth"), std::string::npos) << m;
  m = message(head + "[tree]\nmethod = \"diffusion\"\nterminals = 100\n");
  EXPECT_NE(m.find("p.toml:6: method 'diffusion' is not available; allowed: vascusynth, cco, dcco, colonisation, lsystem"), std::string::npos) << m;
  // dcco's terminals come per [[stage]]; a [[stage]] table in a cco file is for method dcco.
  m = message(head + "[tree]\nmethod = \"dcco\"\nterminals = 100\n");
  EXPECT_NE(m.find("p.toml:7: 'terminals' in [tree] is for method"), std::string::npos) << m;
  m = message(head + "[tree]\nmethod = \"cco\"\nterminals = 100\n\n[[stage]]\nterminals = 5\n");
  EXPECT_NE(m.find("p.toml:9: [stage] is for method dcco, not cco"), std::string::npos) << m;
}

}  // namespace
}  // namespace angiosynth
