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

inline std::filesystem::path scratchDir() {
  static const std::filesystem::path d = [] {
    auto p = std::filesystem::temp_directory_path() / ("angiosynth-fuzz-" + std::to_string(::getpid()));
    std::filesystem::create_directories(p);
    return p;
  }();
  return d;
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
