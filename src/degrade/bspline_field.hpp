#pragma once
// A smooth field on a voxel grid: a uniform cubic B-spline whose coefficients sit on a coarse
// lattice (spacing h per axis, in mm) that covers the grid with one control point beyond each
// face. Bias fields, textures and warps are all such fields.
//
// Evaluating all voxels costs ~4 multiply-adds each: the x and y sums are done once per lattice
// plane (prepare()), and atVoxel() only sums the four z planes.
#include <array>
#include <cstdint>
#include <vector>

#include "core/vec3.hpp"
#include "raster/volume.hpp"

namespace angiosynth {

class BSplineField {
 public:
  BSplineField(const VolumeGrid& grid, const Vec3& spacing_mm);

  const std::array<int, 3>& lattice() const { return n_; }
  Vec3 spacing() const { return h_; }
  Vec3 latticeOrigin() const { return lattice_origin_; }  // control point (0,0,0), mm
  // Coefficients, x fastest; set them, then call prepare().
  std::vector<float>& coefficients() { return coef_; }
  const std::vector<float>& coefficients() const { return coef_; }
  void prepare();

  // The field at voxel (i, j, k) of the grid; needs prepare().
  float atVoxel(std::int64_t i, std::int64_t j, std::int64_t k) const {
    const auto& w = z_.w[k];
    const std::int64_t plane = std::int64_t(grid_.dims[0]) * grid_.dims[1];
    const float* b = xy_.data() + i + grid_.dims[0] * j + plane * z_.first[k];
    return w[0] * b[0] + w[1] * b[plane] + w[2] * b[2 * plane] + w[3] * b[3 * plane];
  }
  // The field and, if asked, its gradient (per mm) at any point in mm (direct 64-term sum).
  double at(const Vec3& p_mm, Vec3* gradient = nullptr) const;

  // Mean over t of Σ B_i(t)² = 151/315: the variance of a field with unit-variance iid
  // coefficients, per axis. Scale coefficients by (315/151)^(3/2) for a unit-variance field.
  static constexpr double kCoefficientGainFor3d = 3.0130088668740;

 private:
  struct AxisWeights {
    std::vector<int> first;  // first of the four control points of each voxel
    std::vector<std::array<float, 4>> w;
  };
  AxisWeights axisWeights(int axis) const;

  VolumeGrid grid_;
  Vec3 h_, lattice_origin_;
  std::array<int, 3> n_;
  std::vector<float> coef_;
  AxisWeights x_, y_, z_;
  std::vector<float> xy_;  // Σ over x and y control points, per voxel column and z control plane
};

// Cubic B-spline basis weights at fractional position u in [0, 1), and their derivatives.
void bsplineWeights(double u, double w[4], double dw[4] = nullptr);

}  // namespace angiosynth
