#pragma once
// A part of a CCO tree grown by domain decomposition, as an array task leaves it for the join:
// binary with exact doubles, so that a tree joined from files is byte for byte the one joined in
// memory. The file carries a fingerprint of the parameters, seed and sample it was grown from,
// and a checksum, so that the join refuses a part of another run or a damaged file.
#include <cstdint>
#include <filesystem>
#include <optional>

#include "grow/cco/decomposition.hpp"

namespace angiosynth {

struct CcoPartKey {
  std::uint64_t fingerprint = 0;  // of the resolved parameters, seed and sample
  int part = 0, parts = 0;
};

// Part `key.part`'s file in a directory of parts.
std::filesystem::path ccoPartFile(const std::filesystem::path& dir, int part);

// Writes the part whole or not at all (files/atomic_file.hpp), replacing an older file.
void writeCcoPartFile(const std::filesystem::path& file, const CcoPart& part, const CcoPartKey& key);

// The part, or nullopt when the file does not exist; InputError when it is not part `key.part`
// of `key.parts` grown from the same parameters, seed and sample, or is damaged.
std::optional<CcoPart> readCcoPartFile(const std::filesystem::path& file, const CcoPartKey& key);

}  // namespace angiosynth
