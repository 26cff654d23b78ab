#include "core/units.hpp"

#include <charconv>
#include <cmath>
#include <map>
#include <stdexcept>
#include <vector>

namespace angiosynth {
namespace {

using Table = std::vector<std::pair<std::string, double>>;

const Table& table(Dimension dim) {
  static const Table length{{"um", 1e-3}, {"µm", 1e-3}, {"mm", 1}, {"cm", 10}, {"m", 1000}, {"voxel", 0}, {"voxels", 0}};
  static const Table flow{{"mm3/s", 1},  {"mm^3/s", 1},        {"mm³/s", 1},         {"uL/s", 1},          {"ul/s", 1},
                          {"µL/s", 1},   {"cm3/s", 1e3},       {"cm^3/s", 1e3},      {"cm³/s", 1e3},       {"mL/s", 1e3},
                          {"ml/s", 1e3}, {"mL/min", 1e3 / 60}, {"ml/min", 1e3 / 60}, {"uL/min", 1.0 / 60}, {"m3/s", 1e9}};
  static const Table pressure{{"Pa", 1}, {"kPa", 1e3}, {"mmHg", kPaPerMmHg}, {"dyn/cm2", 0.1}, {"dyn/cm^2", 0.1}, {"Ba", 0.1}, {"cmH2O", 98.0665}};
  static const Table viscosity{{"Pa*s", 1}, {"Pa.s", 1}, {"Pa·s", 1}, {"mPa*s", 1e-3}, {"mPa.s", 1e-3}, {"mPa·s", 1e-3}, {"cP", 1e-3}, {"P", 0.1}};
  switch (dim) {
    case Dimension::Length: return length;
    case Dimension::Flow: return flow;
    case Dimension::Pressure: return pressure;
    case Dimension::Viscosity: return viscosity;
  }
  return length;
}

const char* dimName(Dimension dim) {
  switch (dim) {
    case Dimension::Length: return "a length";
    case Dimension::Flow: return "a flow";
    case Dimension::Pressure: return "a pressure";
    case Dimension::Viscosity: return "a viscosity";
  }
  return "";
}

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t") - b + 1);
}

}  // namespace

std::string allowedUnits(Dimension dim) {
  std::string out;
  for (const auto& [name, f] : table(dim)) {
    if (name.find("µ") != std::string::npos || name.find("³") != std::string::npos) continue;
    out += (out.empty() ? "" : ", ") + name;
  }
  return out;
}

double parseQuantity(const std::string& text, Dimension dim, double voxel_mm) {
  const std::string s = trim(text);
  double value = 0;
  const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
  const std::string expect = std::string("expected ") + dimName(dim) + " as \"<number> <unit>\" with unit one of " + allowedUnits(dim);
  if (ec != std::errc() || !std::isfinite(value)) throw std::invalid_argument("'" + text + "' is not a number with a unit; " + expect);
  const std::string unit = trim(std::string(ptr, s.data() + s.size()));
  if (unit.empty()) throw std::invalid_argument("'" + text + "' has no unit; " + expect);
  for (const auto& [name, factor] : table(dim)) {
    if (name != unit) continue;
    if (factor == 0) {  // voxel
      if (voxel_mm <= 0) throw std::invalid_argument("'" + text + "': voxel units need a voxel size");
      return value * voxel_mm;
    }
    return value * factor;
  }
  throw std::invalid_argument("unknown unit '" + unit + "' in '" + text + "'; " + expect);
}

double lengthUnitInMm(const std::string& unit) {
  for (const auto& [name, factor] : table(Dimension::Length))
    if (name == unit && factor > 0) return factor;
  throw std::invalid_argument("unknown length unit '" + unit + "'; allowed: um, mm, cm, m");
}

}  // namespace angiosynth
