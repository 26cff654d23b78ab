#pragma once
// Units are converted once, at the edge: internally lengths are mm, flows mm^3/s,
// pressures Pa, viscosities Pa*s.
#include <string>

namespace angiosynth {

enum class Dimension { Length, Flow, Pressure, Viscosity };

// One mmHg in Pa (the conventional value, 13.5951 g/cm³ mercury at standard gravity).
inline constexpr double kPaPerMmHg = 133.322387415;

// Parses "<number> <unit>" (e.g. "0.4 mm", "100 mmHg", "3.6 mPa*s", "8.33 cm3/s") into the
// internal unit of `dim`. The length unit "voxel" needs voxel_mm > 0. Throws
// std::invalid_argument whose message says what is allowed.
double parseQuantity(const std::string& text, Dimension dim, double voxel_mm = 0);

// Units accepted for a dimension, for error messages and the docs.
std::string allowedUnits(Dimension dim);

// Size of a plain length unit (um, mm, cm, m) in mm; throws std::invalid_argument.
double lengthUnitInMm(const std::string& unit);

// A coherent (length, gram, second) unit system, as VascuSynth's unit-less files imply:
// with cm it is CGS (flow cm^3/s, pressure dyn/cm^2 = 0.1 Pa, viscosity poise = 0.1 Pa*s).
struct CoherentUnits {
  std::string length = "cm";
  double mm_per_length = 10;
  double mm3s_per_flow() const { return mm_per_length * mm_per_length * mm_per_length; }
  double pa_per_pressure() const { return 1.0 / mm_per_length; }
  double pas_per_viscosity() const { return 1.0 / mm_per_length; }
  std::string flowName() const { return length + "^3/s"; }
  std::string pressureName() const { return "g/(" + length + "*s^2)"; }
  std::string viscosityName() const { return "g/(" + length + "*s)"; }
};

}  // namespace angiosynth
