#include "settings/input_paths.hpp"

#include "core/error.hpp"

namespace angiosynth {

std::filesystem::path resolveInputPath(const std::filesystem::path& named, const std::filesystem::path& param_file, int line) {
  if (named.is_absolute()) return named;
  const auto beside = param_file.parent_path() / named;
  if (std::filesystem::exists(beside)) return beside;
  if (std::filesystem::exists(named)) return named;
  throw InputError(param_file.string(), line,
                   "no such file '" + named.string() + "' (looked beside the parameter file, " + beside.string() + ", and in the working directory)");
}

}  // namespace angiosynth
