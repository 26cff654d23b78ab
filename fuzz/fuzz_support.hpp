#pragma once
// What every fuzz target shares: the input goes to a file (the parsers read files, as users give
// them), and the program's contract is checked: bad input may only raise InputError (exit 2 with
// file:line); any other exception is an internal error and aborts, so libFuzzer keeps the case.
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/error.hpp"

namespace angiosynth::fuzz {

// One directory per process, removed when the process exits normally, so fuzzing leaves no files
// behind. A crashing case keeps it: the input that crashed is then still there to look at.
class ScratchDir {
 public:
  ScratchDir() : path_(std::filesystem::temp_directory_path() / ("angiosynth-fuzz-" + std::to_string(::getpid()))) {
    std::filesystem::create_directories(path_);
  }
  ~ScratchDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

inline std::filesystem::path scratchDir() {
  static const ScratchDir d;
  return d.path();
}

inline std::filesystem::path writeInput(const std::uint8_t* data, std::size_t size, const std::string& name) {
  const auto p = scratchDir() / name;
  std::ofstream(p, std::ios::binary | std::ios::trunc).write(reinterpret_cast<const char*>(data), std::streamsize(size));
  return p;
}

template <class F>
int expectOnlyInputErrors(F&& f) {
  try {
    f();
  } catch (const InputError&) {
  } catch (const std::exception& e) {
    std::fprintf(stderr, "internal error (not an InputError): %s\n", e.what());
    std::abort();
  }
  return 0;
}

constexpr std::uint64_t kMemoryLimit = 32ull << 20;  // what a fuzz case may use: refusals are exercised, big maps are not built

}  // namespace angiosynth::fuzz
