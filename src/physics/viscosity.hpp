#pragma once
// Blood viscosity as a function of vessel radius. DCCO (Maso Talou et al. 2021 eqs. 8–9) uses the in-vivo law
// of Pries et al. 1994 at discharge haematocrit 0.45, with D = 2000 r (µm from mm):
//   η = 1.125 mPa·s · (κ + κ² (6 e^(−0.085 D) + 2.2 − 2.44 e^(−0.06 D^e))),  κ = (D / (D − 1.1))²
// with Pries' exponent e = 0.645 (the paper prints 0.64; selectable). Radii below 0.55 µm (where
// κ diverges) are refused by the reader; growth never makes them.
namespace angiosynth {

enum class ViscosityModel { Constant, Pries };

struct Viscosity {
  ViscosityModel model = ViscosityModel::Constant;
  double constant = 3.6e-3;  // Pa*s (model Constant; also Algorithm 1's starting value)
  double exponent = 0.645;   // e of the Pries law
  // Pa*s at radius r (mm).
  double at(double radius_mm) const;
};

// The Pries in-vivo law alone, in Pa*s.
double priesViscosity(double radius_mm, double exponent = 0.645);

}  // namespace angiosynth
