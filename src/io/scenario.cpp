#include "io/scenario.hpp"

#include "core/error.hpp"

namespace angiosynth {

std::filesystem::path resolveInputPath(const std::filesystem::path& named, const std::filesystem::path& param_file,
                                       int line) {
  if (named.is_absolute()) return named;
  const auto beside = param_file.parent_path() / named;
  if (std::filesystem::exists(beside)) return beside;
  if (std::filesystem::exists(named)) return named;
  throw InputError(param_file.string(), line,
                   "no such file '" + named.string() + "' (looked beside the parameter file, " + beside.string() +
                       ", and in the working directory)");
}

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
