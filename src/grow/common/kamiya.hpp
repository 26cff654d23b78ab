#pragma once
// Kamiya's bifurcation iteration (Kamiya & Togawa 1972, as used by Karch 1999 and OpenCCO;
// Kerautret et al. (OpenCCO) §3.2, eqs. 9–13). Given the parent's proximal end x0, the split segment's distal end
// x1, the new terminal x2 and the flows f0 = f1 + f2, each step
//   1. takes the lengths l_i = |x_i − x| and the pressure drops (in units of 8η/π)
//      Δ_i = f0 l0 / r0⁴ + f_i l_i / r_i⁴ with the radii of the previous step;
//   2. solves Δ_1, Δ_2 together with Kamiya's law r0^(3+γ)/f0 = r1^(3+γ)/f1 + r2^(3+γ)/f2 for
//      r1, r2 (two non-linear equations; Ceres' TinySolver, Levenberg–Marquardt with automatic
//      derivatives, in log r² so radii stay positive);
//   3. moves x to the volume-weighted centre Σ x_i r_i²/l_i / Σ r_i²/l_i (eq. 13),
// until x moves less than `tolerance` × (l0 + l1 + l2). For γ = 3 the law is Kamiya's own
// r0⁶/f0 = Σ r_i⁶/f_i. The iteration is invariant under scaling all radii, flows or lengths.
#include "core/vec3.hpp"

namespace angiosynth {

struct KamiyaProblem {
  Vec3 x0, x1, x2;
  double f1 = 1, f2 = 1;          // f0 = f1 + f2
  double r0 = 1, r1 = 1, r2 = 1;  // starting radii (Kerautret et al. (OpenCCO): all equal, from the current tree)
  double murray_exponent = 3;
};

struct KamiyaResult {
  Vec3 x;  // bifurcation point, in the plane of x0, x1, x2
  double r0 = 0, r1 = 0, r2 = 0;
  int iterations = 0;
  bool converged = false;  // x settled and every radius solve reached its equations
  bool merged = false;     // the optimum is one of x0, x1, x2 (a zero-length segment)
};

KamiyaResult kamiyaBifurcation(const KamiyaProblem& p, int max_iterations = 100, double tolerance = 1e-6);

}  // namespace angiosynth
