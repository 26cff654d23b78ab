#pragma once
// The values of the distractor label a degraded image comes with: structures it shows that are
// not vessels (degrade/distractors.cpp places them; score counts the false positives on them).
#include <cstdint>

namespace angiosynth {

enum class DistractorKind : std::uint8_t { Blob = 1, Tube = 2, Plate = 3, Bone = 4, Calcification = 5 };
constexpr int kDistractorKinds = 5;

// Names by value ("none" for 0), for records, results and docs.
constexpr const char* distractorName(std::uint8_t kind) {
  constexpr const char* names[] = {"none", "blob", "tube", "plate", "bone", "calcification"};
  return kind <= kDistractorKinds ? names[kind] : "unknown";
}

}  // namespace angiosynth
