#pragma once
#include <filesystem>

namespace angiosynth {

// Resolves a path named in a parameter file: relative to that file's directory if it exists
// there, else relative to the working directory (VascuSynth's convention).
std::filesystem::path resolveInputPath(const std::filesystem::path& named, const std::filesystem::path& param_file, int line);

}  // namespace angiosynth
