#pragma once
// Range checks shared by both parameter formats; each names the file line and the allowed range.
#include <cmath>
#include <string>

#include "core/error.hpp"
#include "core/format.hpp"
#include "core/physical_ranges.hpp"
#include "core/vec3.hpp"

namespace angiosynth {

struct Where {
  std::string file;
  int line;
};

inline std::string show3(const Vec3& v) { return show(v.x) + " " + show(v.y) + " " + show(v.z); }

// lo < v (open) or lo <= v (closed), likewise for hi.
inline void checkRange(double v, double lo, bool lo_open, double hi, bool hi_open, const Where& w, const std::string& what) {
  const bool ok = (lo_open ? v > lo : v >= lo) && (hi_open ? v < hi : v <= hi);
  if (!ok)
    throw InputError(w.file, w.line,
                     what + " = " + show(v) + " is out of range; allowed: " + (lo_open ? "(" : "[") + show(lo) + ", " +
                         (std::isinf(hi) ? "inf" : show(hi)) + (hi_open ? ")" : "]"));
}

// A name the program writes into graph files, file names and tables (a tree's id or kind): 1 to
// 60 letters, digits, '_', '-' and '.', so GXL, GraphML, DOT and CSV take it as it is. Returns
// what is wrong, or "".
inline std::string nameProblem(const std::string& name, const std::string& what) {
  static const char* kAllowed = "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-.";
  if (!name.empty() && name.size() <= 60 && name.find_first_not_of(kAllowed) == std::string::npos) return {};
  return what + " '" + name + "'; allowed: 1 to 60 letters, digits, '_', '-' and '.' (it names the tree in graph files)";
}

// The growth and physics limits, in one place for both formats.
struct Limits {
  static constexpr double kMaxTerminals = 5e6;
  // A CCO tree grown in parts ([tree] parts): each part stays within one process's reach.
  static constexpr double kMaxTerminalsInParts = 1e8;
  static constexpr double kMaxNeighbours = 100;
  static constexpr double kMinMurray = 1, kMaxMurray = 10;  // γ in (1, 10]
  static constexpr double kMaxCostExponent = 10;            // λ, μ in [0, 10]
  // Finite, physically generous bounds: far beyond any vessel, small enough that no product of
  // them overflows a double or a grid index.
  static constexpr double kMinVoxel = physical::kMinStepMm, kMaxVoxel = physical::kMaxStepMm;        // mm
  static constexpr double kMaxLength = physical::kMaxLengthMm;                                       // mm: lengths, distances, fields of view
  static constexpr double kMinRadius = physical::kMinRadiusMm, kMaxRadius = physical::kMaxRadiusMm;  // mm
  static constexpr double kMaxVoxelsPerAxis = 1e5;
  static constexpr double kMinViscosity = 1e-6, kMaxViscosity = 1e3;  // Pa*s (blood: 3.6e-3)
  static constexpr double kMaxPressure = 1e8;                         // Pa (1000 bar)
  static constexpr double kMinPressureDrop = 1e-3;                    // Pa
  static constexpr double kMinFlow = 1e-9, kMaxFlow = 1e12;           // mm^3/s
  static constexpr double kMaxSupplyCutoff = 1e6;                     // map voxels
  static constexpr double kMaxIntensity = 1e12;                       // image intensities
};

}  // namespace angiosynth
