#include "config/scenario.hpp"

#include "core/error.hpp"

namespace angiosynth {

Scenario readParameters(const std::filesystem::path& file, const ReadOptions& opt) {
  std::error_code ec;
  if (std::filesystem::is_directory(file, ec))
    throw InputError(file.string(), 0, "is a directory; give a parameter file (.toml, or VascuSynth's KEY: value format)");
  return file.extension() == ".toml" ? readTomlParameters(file) : readVascuSynthParameters(file, opt);
}

std::vector<std::filesystem::path> scenarioInputs(const Scenario& sc) {
  std::vector<std::filesystem::path> in{sc.parameter_file};
  if (sc.growth)
    for (const auto& p : sc.growth->inputs()) in.push_back(p);
  for (const auto& p : sc.profiles)
    if (std::filesystem::exists(p)) in.push_back(p);
  return in;
}

}  // namespace angiosynth
