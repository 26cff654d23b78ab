#include "degrade/bspline_field.hpp"

#include <algorithm>
#include <cmath>

#include <tbb/parallel_for.h>

namespace angiosynth {

void bsplineWeights(double u, double w[4], double dw[4]) {
  const double v = 1 - u, u2 = u * u, u3 = u2 * u;
  w[0] = v * v * v / 6;
  w[1] = (3 * u3 - 6 * u2 + 4) / 6;
  w[2] = (-3 * u3 + 3 * u2 + 3 * u + 1) / 6;
  w[3] = u3 / 6;
  if (dw) {
    dw[0] = -v * v / 2;
    dw[1] = (3 * u2 - 4 * u) / 2;
    dw[2] = (-3 * u2 + 2 * u + 1) / 2;
    dw[3] = u2 / 2;
  }
}

BSplineField::BSplineField(const VolumeGrid& grid, const Vec3& spacing_mm) : grid_(grid), h_(spacing_mm) {
  double o[3];
  for (int ax = 0; ax < 3; ++ax) {
    const double extent = (grid.dims[ax] - 1) * grid.spacing_mm[ax];
    n_[ax] = static_cast<int>(std::floor(extent / h_[ax])) + 4;
    o[ax] = grid.origin_mm[ax] - h_[ax];
  }
  lattice_origin_ = Vec3(o[0], o[1], o[2]);
  coef_.assign(std::size_t(n_[0]) * n_[1] * n_[2], 0.0f);
  x_ = axisWeights(0);
  y_ = axisWeights(1);
  z_ = axisWeights(2);
}

BSplineField::AxisWeights BSplineField::axisWeights(int axis) const {
  AxisWeights a;
  const int d = grid_.dims[axis];
  a.first.resize(d);
  a.w.resize(d);
  for (int i = 0; i < d; ++i) {
    const double t = (grid_.origin_mm[axis] + i * grid_.spacing_mm[axis] - lattice_origin_[axis]) / h_[axis];
    const int f = std::clamp(static_cast<int>(std::floor(t)), 1, n_[axis] - 3);
    double w[4];
    bsplineWeights(t - f, w);
    a.first[i] = f - 1;
    for (int c = 0; c < 4; ++c) a.w[i][c] = static_cast<float>(w[c]);
  }
  return a;
}

void BSplineField::prepare() {
  const std::int64_t nx = grid_.dims[0], ny = grid_.dims[1];
  const std::int64_t cx = n_[0], cy = n_[1], cz = n_[2];
  xy_.assign(std::size_t(nx * ny * cz), 0.0f);
  tbb::parallel_for(std::int64_t(0), cz, [&](std::int64_t kz) {
    std::vector<float> ax(std::size_t(nx * cy));  // Σ over x control points: (voxel i, control y)
    for (std::int64_t jy = 0; jy < cy; ++jy)
      for (std::int64_t i = 0; i < nx; ++i) {
        const float* c = coef_.data() + x_.first[i] + cx * (jy + cy * kz);
        const auto& w = x_.w[i];
        ax[i + nx * jy] = w[0] * c[0] + w[1] * c[1] + w[2] * c[2] + w[3] * c[3];
      }
    for (std::int64_t j = 0; j < ny; ++j) {
      const auto& w = y_.w[j];
      const float* a = ax.data() + nx * y_.first[j];
      float* out = xy_.data() + nx * (j + ny * kz);
      for (std::int64_t i = 0; i < nx; ++i) out[i] = w[0] * a[i] + w[1] * a[i + nx] + w[2] * a[i + 2 * nx] + w[3] * a[i + 3 * nx];
    }
  });
}

double BSplineField::at(const Vec3& p, Vec3* gradient) const {
  int first[3];
  double w[3][4], dw[3][4];
  for (int ax = 0; ax < 3; ++ax) {
    const double t = (p[ax] - lattice_origin_[ax]) / h_[ax];
    const int f = std::clamp(static_cast<int>(std::floor(t)), 1, n_[ax] - 3);
    bsplineWeights(std::clamp(t - f, 0.0, 1.0), w[ax], dw[ax]);
    first[ax] = f - 1;
  }
  double v = 0, gx = 0, gy = 0, gz = 0;
  for (int c = 0; c < 4; ++c)
    for (int b = 0; b < 4; ++b)
      for (int a = 0; a < 4; ++a) {
        const double k = coef_[std::size_t(first[0] + a) + std::size_t(n_[0]) * (first[1] + b + std::size_t(n_[1]) * (first[2] + c))];
        v += k * w[0][a] * w[1][b] * w[2][c];
        gx += k * dw[0][a] * w[1][b] * w[2][c];
        gy += k * w[0][a] * dw[1][b] * w[2][c];
        gz += k * w[0][a] * w[1][b] * dw[2][c];
      }
  if (gradient) *gradient = Vec3(gx / h_.x, gy / h_.y, gz / h_.z);
  return v;
}

}  // namespace angiosynth
