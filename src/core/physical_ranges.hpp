#pragma once
// The physical ranges of lengths, radii and coordinates, in one place: the five graph readers,
// the parameter files and the command-line options all hold their values to these, so they agree
// on what a vessel can be. Generous beyond any vasculature, and small enough that no product of
// them overflows a double, a grid index or a triangle count.
#include <cmath>
#include <string>

#include "core/error.hpp"
#include "core/format.hpp"

namespace angiosynth::physical {

inline constexpr double kMaxCoordinateMm = 1e6;  // |x|, |y|, |z| of a point: 1 km from the origin
inline constexpr double kMaxLengthMm = 1e6;      // lengths, distances, fields of view
inline constexpr double kMinRadiusMm = 1e-4;     // 0.1 µm: far below a capillary's 2–5 µm
inline constexpr double kMaxRadiusMm = 1e3;      // 1 m: far beyond an aorta's 15 mm
inline constexpr double kMinStepMm = 1e-4;       // voxels, grid steps and curve pieces: 0.1 µm …
inline constexpr double kMaxStepMm = 1e4;        // … 10 m
// Children of one node of a graph file. Vascular junctions have two to four; a node with
// hundreds is a skeletonisation artefact, and each N-ary junction becomes a chain of links whose
// length every walk through the tree pays.
inline constexpr int kMaxJunctionChildren = 64;

// A radius: in [kMinRadiusMm, kMaxRadiusMm], or 0 where `zero_means_unset` (a graph file may
// leave radii to the growth that continues it).
inline void checkRadius(double r_mm, const std::string& file, int line, const std::string& what, bool zero_means_unset = false) {
  if (zero_means_unset && r_mm == 0) return;
  if (!(r_mm >= kMinRadiusMm && r_mm <= kMaxRadiusMm))
    throw InputError(file, line,
                     what + " " + show(r_mm) + " mm is out of range; allowed: " + show(kMinRadiusMm) + " to " + show(kMaxRadiusMm) + " mm" +
                         (zero_means_unset ? " (or 0: not given)" : ""));
}

inline void checkCoordinate(double v_mm, const std::string& file, int line, const std::string& what) {
  if (!(std::abs(v_mm) <= kMaxCoordinateMm))
    throw InputError(file, line,
                     what + " " + show(v_mm) + " mm is out of range; allowed: -" + show(kMaxCoordinateMm) + " to " + show(kMaxCoordinateMm) + " mm");
}

// A length or distance in (0, kMaxLengthMm] (or [0, …] with `zero_allowed`).
inline void checkLength(double v_mm, const std::string& file, int line, const std::string& what, bool zero_allowed = false) {
  if (!((zero_allowed ? v_mm >= 0 : v_mm > 0) && v_mm <= kMaxLengthMm))
    throw InputError(
        file, line,
        what + " " + show(v_mm) + " mm is out of range; allowed: " + (zero_allowed ? "0" : "more than 0") + " to " + show(kMaxLengthMm) + " mm");
}

}  // namespace angiosynth::physical
