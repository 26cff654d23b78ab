#pragma once
// Poiseuille flow in a tree with equal terminal flows, Murray's law with exponent γ, and radii
// fixed by the root pressure drop (Hamarneh & Jassi 2010 §2, §3.7–3.8; Karch 1999). Reduced resistances are
// stored without the constant 8η/π, i.e. in mm: R̃_i = l_i + [β_a⁴/R̃_a + β_b⁴/R̃_b]⁻¹.
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

#include "core/vascular_tree.hpp"

namespace angiosynth {

struct PhysicsParameters {
  double murray_exponent = 3;         // γ
  double cost_radius_exponent = 2;    // λ
  double cost_length_exponent = 1;    // μ
  double viscosity = 3.6e-3;          // Pa*s
  double perfusion_pressure = 13300;  // Pa, at the root (a vein's outlet)
  double terminal_pressure = 8300;    // Pa
  double perfusion_flow = 8330;       // mm^3/s, split equally among the final terminals
  std::int64_t total_terminals = 1;   // N: every terminal carries perfusion_flow / N
  // γ by the parent's radius instead of one γ everywhere (measured exponents fall from about 3 in
  // arterioles to about 2.3 in large arteries): band edges in mm, ascending, and one exponent per
  // band (edges + 1). Empty: murray_exponent at every bifurcation.
  std::vector<double> murray_band_edges;
  std::vector<double> murray_band_exponents;
  double terminalFlow() const { return perfusion_flow / static_cast<double>(total_terminals); }
  // Flow runs from the terminals to the root (a vein): the terminals are at the higher pressure.
  bool drains() const { return terminal_pressure > perfusion_pressure; }
};

// x^(-1/3) for x >= 1 to full double precision: a first guess from the exponent bits, then
// Newton steps y ← y(4 − x y³)/3 (quadratic convergence: rounding level, worst 6e-16 relative over [1, 1e12], from
// the guess's few-percent error in four steps). About four times cheaper than 1/std::cbrt in the growth loop.
inline double inverseCbrt(double x) {
  std::uint64_t bits;
  std::memcpy(&bits, &x, sizeof bits);
  bits = 0x553ef0ff289dd796ULL - bits / 3;  // exponent of x^(-1/3)
  double y;
  std::memcpy(&y, &bits, sizeof y);
  for (int i = 0; i < 4; ++i) y = y * (4.0 - x * y * y * y) * (1.0 / 3.0);
  return y;
}

// Murray's exponent as a function of the parent's radius: one γ, or one per radius band. Across
// an edge γ runs linearly in log r over ±5 % of the edge's radius: with a step, a parent whose
// radius sits at an edge could have no consistent band (its band sets the radii that set its
// band); with the ramp the radii and exponents have a fixed point, which solveTree finds.
class MurrayLaw {
 public:
  static constexpr int kMaxBands = 8;
  static constexpr double kRampHalfWidth = 0.04879016416943205;  // ln 1.05
  MurrayLaw() { exponent_[0] = 3; }
  // γ everywhere, or by band when band_exponents (one more than band_edges, mm) are given.
  MurrayLaw(double exponent, const std::vector<double>& band_edges, const std::vector<double>& band_exponents);
  explicit MurrayLaw(const PhysicsParameters& p) : MurrayLaw(p.murray_exponent, p.murray_band_edges, p.murray_band_exponents) {}
  bool banded() const { return bands_ > 1; }
  double exponentAt(double parent_radius_mm) const {
    if (bands_ == 1) return exponent_[0];
    const double x = parent_radius_mm > 0 ? std::log(parent_radius_mm) : -1e300;
    for (int k = 0; k + 1 < bands_; ++k) {
      if (x <= log_edge_[k] - kRampHalfWidth) return exponent_[k];
      if (x < log_edge_[k] + kRampHalfWidth)
        return exponent_[k] + (x - (log_edge_[k] - kRampHalfWidth)) / (2 * kRampHalfWidth) * (exponent_[k + 1] - exponent_[k]);
    }
    return exponent_[bands_ - 1];
  }
  // The parent's radius from its daughters' (methods that size vessels from the leaves up):
  // r^γ(r) = r_a^γ(r) + r_b^γ(r), by bisection between max(r_a, r_b) and r_a + r_b when banded.
  double parentRadius(double r_a, double r_b) const;

 private:
  int bands_ = 1;
  std::array<double, kMaxBands> exponent_{};
  std::array<double, kMaxBands - 1> log_edge_{};
};

// Powers with fast paths for the usual exponents (γ = 3, λ = 2, μ = 1); used in inner loops. With
// banded γ the bifurcation's γ comes from its parent's radius (the `parent_radius` arguments).
class PowerKernel {
 public:
  explicit PowerKernel(const PhysicsParameters& p)
      : law_(p),
        gamma_(p.murray_exponent),
        lambda_(p.cost_radius_exponent),
        mu_(p.cost_length_exponent),
        gamma3_(gamma_ == 3.0 && !law_.banded()),
        lambda2_(lambda_ == 2.0),
        mu1_(mu_ == 1.0) {}

  struct Split {
    double beta_a, beta_b;
  };
  // Radius ratios of two children a, b to their parent: r_a/r_b = (n_a R̃_a / n_b R̃_b)^¼ (eq. 12)
  // and β = (1 + (r_other/r_self)^γ)^(-1/γ) (eq. 11).
  Split split(double n_a, double R_a, double n_b, double R_b, double parent_radius = 0) const {
    const double y = (n_b * R_b) / (n_a * R_a);  // (r_b/r_a)^4
    const double q = std::sqrt(std::sqrt(y));    // r_b/r_a
    if (gamma3_) {
      const double beta_a = inverseCbrt(1.0 + q * q * q);
      return {beta_a, beta_a * q};
    }
    const double g = gammaAt(parent_radius);
    const double beta_a = std::pow(1.0 + std::pow(q, g), -1.0 / g);
    return {beta_a, beta_a * q};
  }
  double radiusCost(double beta) const { return lambda2_ ? beta * beta : std::pow(beta, lambda_); }
  double lengthCost(double l) const { return mu1_ ? l : std::pow(l, mu_); }
  double murray(double r, double parent_radius = 0) const { return gamma3_ ? r * r * r : std::pow(r, gammaAt(parent_radius)); }
  double gammaAt(double parent_radius) const { return law_.banded() ? law_.exponentAt(parent_radius) : gamma_; }
  const MurrayLaw& law() const { return law_; }

 private:
  MurrayLaw law_;
  double gamma_, lambda_, mu_;
  bool gamma3_, lambda2_, mu1_;
};

inline double pow4(double x) { return (x * x) * (x * x); }

// R̃ of a node whose children a, b have ratios `s`: l + [β_a⁴/R̃_a + β_b⁴/R̃_b]⁻¹.
inline double combinedResistance(double l, const PowerKernel::Split& s, double R_a, double R_b) {
  return l + 1.0 / (pow4(s.beta_a) / R_a + pow4(s.beta_b) / R_b);
}

// Root radius from r⁴ = Q_root·(8η/π)·R̃_root / |P_root − P_term| (eq. 10).
double rootRadius(const PhysicsParameters& p, double root_flow, double root_reduced_resistance);

// Recomputes terminal counts, lengths, reduced resistances, β, cost ratios (bottom-up) and then
// radii, flows and pressures (top-down) of the whole tree from its geometry alone: O(N). A node
// with one child lies inside a vessel: both segments keep one radius, their resistances in series. With
// banded γ the two passes repeat, each bifurcation's γ taken from its parent's radius of the pass
// before, until every γ is the law's at the final radii (to 1e-13): returns the passes made.
int solveTree(VascularTree& tree, const PhysicsParameters& p);

// Σ l^μ r^λ over all segments, in mm^(μ+λ).
double treeCost(const VascularTree& tree, const PhysicsParameters& p);
// Σ π r² l, in mm^3.
double treeVolume(const VascularTree& tree);

}  // namespace angiosynth
