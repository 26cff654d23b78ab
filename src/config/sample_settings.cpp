#include "config/sample_settings.hpp"

#include "settings/param_checks.hpp"

namespace angiosynth {

// clang-format off
const std::vector<Setting<CurveOptions>>& curveSettings() {
  using P = CurveOptions;
  static const std::vector<Setting<P>> settings{
      {.table = "curves", .key = "tortuosity", .unit = "", .fallback = "1.2",
       .meaning = "with a [curves] table, every vessel becomes a smooth curve whose arc length over chord is this (1 … 3)",
       .field = &P::tortuosity, .range = {1, 3}},
      {.table = "curves", .key = "tortuosity_sd", .unit = "", .fallback = "0",
       .meaning = "normal spread of the target between vessels (0 … 1; relative to sum_of_angles when that is the target)",
       .field = &P::tortuosity_sd, .range = {0, 1}},
      {.table = "curves", .key = "sum_of_angles", .unit = "rad/mm", .fallback = "none",
       .meaning = "instead of tortuosity: each vessel's sum of angles per mm (Bullitt et al. 2003), as stats measures it (0 … 20)",
       .field = &P::sum_of_angles, .range = {0, 20, true, false}},
      {.table = "curves", .key = "wavelength", .unit = "mm", .fallback = "40 × the vessel's radius",
       .meaning = "the curve's wavelength (or wavelength_radii, multiples of each vessel's radius)",
       .field = &P::wavelength_mm, .range = {0, Limits::kMaxLength, true, false}, .quantity = Dimension::Length},
      {.table = "curves", .key = "wavelength_radii", .unit = "", .fallback = "40",
       .meaning = "the curve's wavelength in multiples of each vessel's radius (≥ 2)", .field = &P::wavelength_radii, .range = {2, 1e4}},
      {.table = "curves", .key = "piece_length", .unit = "mm", .fallback = "1 voxel",
       .meaning = "the longest straight piece a curve is drawn with (none shorter than an eighth of its vessel's radius)",
       .field = &P::piece_mm, .range = {Limits::kMinVoxel, Limits::kMaxLength}, .quantity = Dimension::Length},
      {.table = "curves", .key = "wall_clearance", .unit = "mm", .fallback = "0 mm", .meaning = "kept beyond the radius (and wall) from the domain's wall",
       .field = &P::wall_clearance_mm, .range = {0, Limits::kMaxLength}, .quantity = Dimension::Length},
      {.table = "curves", .key = "avoid_overlaps", .unit = "true/false", .fallback = "true", .meaning = "flatten a curve that would touch another vessel",
       .field = &P::avoid_overlaps},
  };
  return settings;
}
// clang-format on

// clang-format off
const std::vector<SettingRule<CurveOptions>>& curveRules() {
  static const std::vector<SettingRule<CurveOptions>> rules{
      {{"wavelength_radii", "wavelength"}, [](const CurveOptions& o) {
         return o.wavelength_mm && o.wavelength_radii
                    ? std::string("give wavelength (a length) or wavelength_radii (multiples of each vessel's radius), not both")
                    : "";
       }},
  };
  return rules;
}
// clang-format on

// clang-format off
const std::vector<Setting<Scenario>>& outputSettings() {
  static const std::vector<Setting<Scenario>> settings{
      {.table = "degrade", .key = "profiles", .unit = "[text]", .fallback = "[]",
       .meaning = "degraded images to write, one image_<name> each: shipped profile names, .toml profiles or VascuSynth noise files",
       .field = &Scenario::profiles},
      {.table = "output", .key = "gxl_dialect", .unit = "text", .fallback = "gxl", .meaning = "gxl (GXL 1.0) or vascusynth",
       .field = &Scenario::gxl_dialect, .choices = {"gxl", "vascusynth"}, .flag = "--gxl-dialect"},
  };
  return settings;
}
// clang-format on

}  // namespace angiosynth
