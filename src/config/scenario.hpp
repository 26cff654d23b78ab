#pragma once
// A validated parameter set in internal units (mm, mm^3/s, Pa, Pa*s), with where every value
// came from, so that later errors (e.g. a root in zero demand) can still point at a file line.
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/units.hpp"
#include "config/image_settings.hpp"
#include "config/mesh_settings.hpp"
#include "settings/input_paths.hpp"
#include "settings/param_checks.hpp"
#include "grow/common/curved_vessels.hpp"
#include "grow/method.hpp"

namespace toml {
inline namespace v3 {
class table;
}
}  // namespace toml

namespace angiosynth {

struct Scenario {
  std::string parameter_file;
  std::string format;                         // "vascusynth" or "toml"
  std::shared_ptr<const GrowthSetup> growth;  // the growth method and its options
  std::optional<std::uint64_t> seed;
  CurveOptions curves;  // [curves]: vessels made curves after growth
  int curves_line = 0;
  ImageParameters image;
  int image_line = 0;  // line of [image], for errors about its size
  MeshParameters mesh;
  int mesh_line = 0;
  std::string gxl_dialect = "gxl";    // "gxl" (GXL 1.0) or "vascusynth"
  std::vector<std::string> profiles;  // [degrade] profiles: names or files
  int profiles_line = 0;
  CoherentUnits input_units;  // only for VascuSynth files
  std::string units_note;
};

struct ReadOptions {
  std::string vascusynth_length_unit = "cm";  // unit of VOXEL_WIDTH in VascuSynth files
  bool vascusynth_rules = false;              // VascuSynth files grown under VascuSynth's own constraints ([tree] rules)
};

// Reads a VascuSynth parameter file (2008 or 2011 keys).
Scenario readVascuSynthParameters(const std::filesystem::path& file, const ReadOptions& opt = {});
// Reads a native TOML parameter file.
Scenario readTomlParameters(const std::filesystem::path& file);
// The same from a parsed table; relative paths are resolved beside `file` (a dataset spec).
Scenario readTomlParameters(const toml::table& root, const std::filesystem::path& file);
// A [mesh] table alone (the Python module's Sample.mesh), read, defaulted and checked as in a
// parameter file; `voxel_mm` is the unit of settings given in voxels.
MeshParameters readMeshParameters(const toml::table& root, const std::filesystem::path& file, double voxel_mm);
// Chooses by extension: .toml is native, anything else VascuSynth.
Scenario readParameters(const std::filesystem::path& file, const ReadOptions& opt = {});

// Every file a scenario reads (parameter file, maps, mask, profile files): outputs must not hold them.
std::vector<std::filesystem::path> scenarioInputs(const Scenario& sc);

}  // namespace angiosynth
