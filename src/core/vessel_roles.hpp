#pragma once
// Per-vessel attributes of staged growth (DCCO, Maso Talou et al. 2021 §1.1.6 and §1.1.9), as VascularTree
// stores them (0: not set) and graphs write them.
#include <cstdint>

namespace angiosynth {

// Where a vessel may lie and branch: distribution vessels inside their stage's domain,
// transport vessels anywhere, perforators anywhere but branching only inside the domain.
enum class VesselRole : std::uint8_t { Unset = 0, Distribution = 1, Transport = 2, Perforator = 3 };
// Where a vessel may take a new branch: anywhere on the triangle lattice (versatile), on its own
// line (fixed), at its distal end (distal), or not at all (none).
enum class Branching : std::uint8_t { Unset = 0, Versatile = 1, Fixed = 2, Distal = 3, None = 4 };

inline const char* roleName(std::uint8_t r) {
  switch (VesselRole(r)) {
    case VesselRole::Distribution: return "distribution";
    case VesselRole::Transport: return "transport";
    case VesselRole::Perforator: return "perforator";
    default: return "";
  }
}
inline const char* branchingName(std::uint8_t b) {
  switch (Branching(b)) {
    case Branching::Versatile: return "versatile";
    case Branching::Fixed: return "fixed";
    case Branching::Distal: return "distal";
    case Branching::None: return "none";
    default: return "";
  }
}

}  // namespace angiosynth
