#pragma once
// What an output path may be. The program deletes only what it wrote, so an output directory must
// never be, or contain, the working directory or an input (a parameter file, a map, a profile):
// replacing such a directory could remove the user's own files.
#include <filesystem>
#include <string>
#include <vector>

namespace angiosynth {

// Throws InputError (exit 2) when `out` is an existing file, is the working directory, or is an
// ancestor of it or of any of `inputs`. `what` names the option ("--out", "name list line 3").
void checkOutputPath(const std::filesystem::path& out, const std::vector<std::filesystem::path>& inputs, const std::string& what);

// One output file of a command (--out, --csv, --plot, OUT) and the option that names it.
struct OutputFile {
  std::filesystem::path path;
  std::string what;
};

// Throws InputError (exit 2, nothing written) when an output file (an empty path: not asked for)
// is a directory, is one of the `inputs` or lies inside an input directory, is the same file as
// another output, or exists while `replace` (--force) is false.
void checkOutputFiles(const std::vector<OutputFile>& outputs, const std::vector<std::filesystem::path>& inputs, bool replace);

// Whether `inner` is `outer` or lies beneath it (both made absolute and normalised, symlinks of
// existing parts resolved).
bool isWithin(const std::filesystem::path& inner, const std::filesystem::path& outer);

// A relative path that stays beneath its base: no root, no "..", not empty. Manifests recorded
// by the program are read back through this, so a crafted manifest cannot reach other files.
bool isConfinedRelativePath(const std::string& rel);

}  // namespace angiosynth
