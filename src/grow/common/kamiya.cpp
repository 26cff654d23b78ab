#include "grow/common/kamiya.hpp"

#include <ceres/tiny_solver.h>
#include <ceres/tiny_solver_autodiff_function.h>

#include <cmath>

namespace angiosynth {
namespace {

// Residuals of the two pressure-drop equations, relative to the targets, in y = log r².
struct KamiyaResidual {
  double d1, d2, f0, f1, f2, l0, l1, l2, e;  // e = 3 + γ
  template <class T>
  bool operator()(const T* y, T* res) const {
    using std::cbrt;
    using std::exp;
    using std::pow;
    const T a1 = exp(y[0]), a2 = exp(y[1]);  // r1², r2²
    T r0_4;
    if (e == 6) {  // γ = 3, Kamiya's own law: r0⁴ = (f0 Σ r_i⁶/f_i)^(2/3)
      const T c = cbrt(f0 * (a1 * a1 * a1 / f1 + a2 * a2 * a2 / f2));
      r0_4 = c * c;
    } else {
      r0_4 = pow(f0 * (pow(a1, 0.5 * e) / f1 + pow(a2, 0.5 * e) / f2), 4.0 / e);  // (r0^e)^(4/e)
    }
    const T trunk = f0 * l0 / r0_4;
    res[0] = T(1.0) - (trunk + f1 * l1 / (a1 * a1)) / d1;
    res[1] = T(1.0) - (trunk + f2 * l2 / (a2 * a2)) / d2;
    return true;
  }
};

double pow4(double x) { return (x * x) * (x * x); }

double parentRadius(double r1, double r2, double f0, double f1, double f2, double e) {
  return std::pow(f0 * (std::pow(r1, e) / f1 + std::pow(r2, e) / f2), 1.0 / e);
}

}  // namespace

KamiyaResult kamiyaBifurcation(const KamiyaProblem& p, int max_iterations, double tolerance) {
  KamiyaResult out;
  const double f1 = p.f1, f2 = p.f2, f0 = f1 + f2, e = 3.0 + p.murray_exponent;
  const Vec3 xs[3] = {p.x0, p.x1, p.x2};
  const double span = distance(p.x0, p.x1) + distance(p.x1, p.x2) + distance(p.x2, p.x0);
  const double floor_len = 1e-12 * span;
  double r0 = p.r0, r1 = p.r1, r2 = p.r2;
  Vec3 x = (p.x0 + p.x1) * 0.5;  // Kerautret et al. (OpenCCO) eq. (8)
  using Solver = ceres::TinySolver<ceres::TinySolverAutoDiffFunction<KamiyaResidual, 2, 2>>;
  Solver solver;
  solver.options.max_num_iterations = 50;
  solver.options.gradient_tolerance = 1e-16;
  solver.options.parameter_tolerance = 1e-14;
  solver.options.function_tolerance = 0;
  solver.options.cost_threshold = 1e-26;
  // The plane of the three points; its normal keeps the Newton system regular.
  const Vec3 n3 = cross(p.x1 - p.x0, p.x2 - p.x0);
  const bool has_plane = norm(n3) > 1e-12 * span * span;
  Eigen::Matrix3d normal_outer = Eigen::Matrix3d::Zero();
  if (has_plane) {
    const Eigen::Vector3d ne(n3.x / norm(n3), n3.y / norm(n3), n3.z / norm(n3));
    normal_outer = ne * ne.transpose();
  }
  const auto lengths = [&](const Vec3& at, double(&l)[3]) {
    for (int i = 0; i < 3; ++i) l[i] = std::max(distance(xs[i], at), floor_len);
  };
  for (int it = 1; it <= max_iterations; ++it) {
    out.iterations = it;
    double l[3];
    lengths(x, l);
    // The radii of step 1 satisfy Kamiya's law and, by construction, reproduce the pressure
    // drops computed from them at every later step, so later solves would return them
    // unchanged: only the first step needs the solver.
    if (it == 1) {
      const double t0 = f0 * l[0] / pow4(r0);
      KamiyaResidual res{t0 + f1 * l[1] / pow4(r1), t0 + f2 * l[2] / pow4(r2), f0, f1, f2, l[0], l[1], l[2], e};
      ceres::TinySolverAutoDiffFunction<KamiyaResidual, 2, 2> fn(res);
      Eigen::Vector2d y(std::log(r1 * r1), std::log(r2 * r2));
      solver.Solve(fn, &y);
      double check[2];
      res(y.data(), check);
      if (!(std::abs(check[0]) < 1e-9 && std::abs(check[1]) < 1e-9) || !y.allFinite()) return out;  // no solution
      r1 = std::sqrt(std::exp(y[0]));
      r2 = std::sqrt(std::exp(y[1]));
      r0 = parentRadius(r1, r2, f0, f1, f2, e);
    }
    if (it == 1) {
      // With the radii fixed, x minimises Σ r_i² |x − x_i|. When that minimum sits on one of the
      // three points (the weighted Fermat condition |Σ_{i≠j} r_i² u_ij| ≤ r_j²), the iteration
      // would only creep towards it: the bifurcation merges into that node.
      const double a[3] = {r0 * r0, r1 * r1, r2 * r2};
      for (int j = 0; j < 3; ++j) {
        Vec3 pull(0, 0, 0);
        for (int i = 0; i < 3; ++i)
          if (i != j) pull = pull + (xs[i] - xs[j]) * (a[i] / std::max(distance(xs[i], xs[j]), floor_len));
        if (norm(pull) <= a[j]) {
          x = xs[j];
          out.converged = true;
          out.merged = true;
          break;
        }
      }
      if (out.merged) break;
    }
    const double a[3] = {r0 * r0, r1 * r1, r2 * r2};
    const double w[3] = {a[0] / l[0], a[1] / l[1], a[2] / l[2]};
    // Eq. (13): the volume-weighted centre. Its fixed point minimises Σ r_i² l_i; a Newton step
    // on that objective (in the plane of the three points) reaches it in a few steps where
    // eq. (13) alone creeps, and is kept only when it lowers the objective.
    Vec3 next = (xs[0] * w[0] + xs[1] * w[1] + xs[2] * w[2]) / (w[0] + w[1] + w[2]);
    if (has_plane) {
      Eigen::Matrix3d H = normal_outer;
      Eigen::Vector3d g = Eigen::Vector3d::Zero();
      for (int i = 0; i < 3; ++i) {
        const Vec3 u = (x - xs[i]) / l[i];
        const Eigen::Vector3d ue(u.x, u.y, u.z);
        g += a[i] * ue;
        H += w[i] * (Eigen::Matrix3d::Identity() - ue * ue.transpose());
      }
      const Eigen::Vector3d d = H.ldlt().solve(-g);
      const Vec3 newton = x + Vec3(d[0], d[1], d[2]);
      const auto objective = [&](const Vec3& at) { return a[0] * distance(at, xs[0]) + a[1] * distance(at, xs[1]) + a[2] * distance(at, xs[2]); };
      if (d.allFinite() && objective(newton) < objective(next)) next = newton;
    }
    const double step = distance(next, x);
    x = next;
    if (step <= tolerance * (l[0] + l[1] + l[2])) {
      out.converged = true;
      break;
    }
  }
  out.x = x;
  out.r0 = r0;
  out.r1 = r1;
  out.r2 = r2;
  return out;
}

}  // namespace angiosynth
