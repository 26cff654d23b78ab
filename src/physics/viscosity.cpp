#include "physics/viscosity.hpp"

#include <cmath>

namespace angiosynth {

double priesViscosity(double radius_mm, double exponent) {
  const double d = 2000.0 * radius_mm;  // diameter, µm
  const double k = (d / (d - 1.1)) * (d / (d - 1.1));
  const double eta045 = 6.0 * std::exp(-0.085 * d) + 3.2 - 2.44 * std::exp(-0.06 * std::pow(d, exponent));
  return 1.125e-3 * (k + k * k * (eta045 - 1.0));
}

double Viscosity::at(double radius_mm) const { return model == ViscosityModel::Pries ? priesViscosity(radius_mm, exponent) : constant; }

}  // namespace angiosynth
