#pragma once
// A degradation profile: an ordered list of effects whose parameters are values or ranges,
// read from noise_profiles/*.toml or from a VascuSynth noise file.
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "degrade/effect.hpp"

namespace angiosynth {

struct EffectSpec {
  const EffectType* type = nullptr;
  std::map<std::string, ParamSpec> params;
  std::optional<ParamSpec> probability;  // of applying the effect at all (default 1)
  int line = 0;
};

struct Profile {
  std::string name;  // role suffix: image_<name>
  std::string file;  // where it was read, for errors and sample.json
  std::string description;
  std::optional<ParamSpec> background;  // tissue intensity (default: [image] background)
  std::optional<ParamSpec> vessel;      // full-vessel intensity (default: [image] vessel)
  std::string dtype;                    // empty: [image] dtype
  bool clamp_each_step = false;         // clamp to dtype's range after every effect (VascuSynth)
  std::vector<EffectSpec> effects;
};

// A native profile (TOML). Unknown keys and effects are errors naming file and line.
Profile readProfileToml(const std::filesystem::path& file);
// VascuSynth's noise file: GAUSSIAN:, UNIFORM:, SALTPEPPER:, SHADOW: lines, on 0–255, uint8,
// clamped after each line as VascuSynth does.
Profile readVascuSynthNoiseFile(const std::filesystem::path& file);

// Where shipped profiles are looked up for a bare name: $ANGIOSYNTH_PROFILE_PATH (':'-separated),
// then the installed and source noise_profiles directories.
std::vector<std::filesystem::path> profileSearchPath();
// A profile named in a parameter file (or on the command line): a bare name ("cta") is a shipped
// profile; a path ending in .toml is a native profile; any other path is a VascuSynth noise file.
// Paths are resolved beside the naming file, then in the working directory.
Profile loadProfile(const std::string& ref, const std::filesystem::path& named_in, int line);

// Replaces one value of a loaded profile: "<effect type>.<parameter>" in every effect of that
// type, or "background" / "vessel". `value` is read as the profile file's would be; errors name
// `file` and the value's line.
void overrideProfileValue(Profile& profile, const std::string& key, const toml::node& value, const std::string& file);

}  // namespace angiosynth
