#pragma once
// Reading a TOML file with errors that name file and line (parameter files, profiles).
#include <toml++/toml.h>

#include <filesystem>
#include <string>

#include "core/error.hpp"

namespace angiosynth {

// `what` names the kind of file in the "no such …" error.
inline toml::table parseTomlFile(const std::filesystem::path& path, const std::string& what) {
  const std::string file = path.string();
  if (!std::filesystem::exists(path)) throw InputError(file, 0, "no such " + what);
  if (!std::filesystem::is_regular_file(path)) throw InputError(file, 0, "the " + what + " is not a regular file (a directory or device)");
  try {
    return toml::parse_file(file);
  } catch (const toml::parse_error& e) {
    throw InputError(file, static_cast<int>(e.source().begin.line), std::string("not valid TOML: ") + std::string(e.description()));
  }
}

}  // namespace angiosynth
