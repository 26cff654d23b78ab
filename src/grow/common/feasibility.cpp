#include "grow/common/feasibility.hpp"

#include <cmath>
#include <numbers>

#include "core/error.hpp"
#include "settings/param_checks.hpp"

namespace angiosynth {

RadiusEstimate estimateRadii(const PhysicsParameters& p, std::int64_t terminals, double measure, int dim) {
  const double n = double(terminals), levels = std::log2(std::max(1.0, n));
  const double root_length = std::pow(measure, 1.0 / dim) / 2;
  double path = 0;  // Σ over levels of 2^-k · 2^(-k/d) · 2^(4k/γ)
  for (int k = 0; k <= int(levels); ++k) path += std::pow(2.0, -k - double(k) / dim + 4.0 * k / p.murray_exponent);
  const double dp = std::abs(p.perfusion_pressure - p.terminal_pressure);
  RadiusEstimate e;
  e.root = std::pow(8 * p.viscosity * p.perfusion_flow * root_length * path / (std::numbers::pi * dp), 0.25);
  e.terminal = e.root * std::pow(n, -1.0 / p.murray_exponent);
  e.spacing = std::pow(measure / n, 1.0 / dim);
  return e;
}

void checkPacking(std::int64_t n, double min_distance_mm, double measure, const std::string& file, int line) {
  if (!(min_distance_mm > 0)) return;
  const double ball = std::numbers::pi / 6 * std::pow(min_distance_mm, 3);
  const double capacity = 0.74 * measure / ball;
  if (double(n) > capacity)
    throw InputError(file, line,
                     std::to_string(n) + " terminals cannot lie " + show(min_distance_mm) + " mm apart in the " + show(measure) +
                         " mm^3 of non-zero demand: at most about " + std::to_string(std::int64_t(capacity)) +
                         " fit (sphere packing); use fewer terminals, a smaller minimum distance, or a larger domain");
}

void checkVesselRoom(const PhysicsParameters& p, std::int64_t n, double measure, int dim, const std::string& file, int line) {
  const RadiusEstimate e = estimateRadii(p, n, measure, dim);
  const std::string unit = dim == 2 ? " mm^2" : " mm^3";
  // Terminal vessels wider than a quarter of the spacing between terminals leave no room to
  // branch without collisions: growth slows steeply well before the limit and runs for minutes
  // past it, while the shipped examples sit far below it (docs/benchmarks.md, "Figures behind
  // design choices").
  if (2 * e.terminal > e.spacing / 4)
    throw InputError(
        file, line,
        "vessels too thick for the domain: this flow, pressure drop and viscosity give terminal vessels of "
        "diameter about " +
            show(2 * e.terminal) + " mm (root radius about " + show(e.root) + " mm), but " + std::to_string(n) + " terminals in " + show(measure) +
            unit + " lie about " + show(e.spacing) +
            " mm apart, and growth needs diameters below a quarter of that; lower perfusion_flow or viscosity, raise the pressure drop, or use "
            "fewer terminals (vessel radius scales with flow^(1/4))");
}

}  // namespace angiosynth
