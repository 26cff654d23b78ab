#pragma once
// Writes a text output through a stream callback and fails loudly if the disk does.
#include <filesystem>
#include <fstream>

#include "core/error.hpp"

namespace angiosynth {

template <class F>
void writeTextFile(const std::filesystem::path& file, F&& write) {
  std::ofstream out(file, std::ios::binary);
  write(out);
  out.flush();
  if (!out) throw InputError(file.string(), 0, "cannot write this file (disk full or no permission?)");
}

}  // namespace angiosynth
