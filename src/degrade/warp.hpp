#pragma once
// A random B-spline free-form deformation, kept invertible, and what it does to volumes, trees
// and labels. The warped image at y shows the clean image at ψ(y) = y + u(y) (the pull-back);
// tree points move the other way, to φ(x) = ψ⁻¹(x).
//
// Invertibility: with control displacements |c| < 0.4 × control spacing on every axis, a cubic
// B-spline deformation is injective (Choi & Lee 2000 give the bound 1/2.48 ≈ 0.403).
#include <array>
#include <memory>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/rng.hpp"
#include "core/vascular_tree.hpp"
#include "degrade/bspline_field.hpp"
#include "raster/ground_truth.hpp"

namespace angiosynth {

class BSplineWarp {
 public:
  static constexpr double kMaxDisplacementPerSpacing = 0.4;

  // Control displacements uniform in [−max, max] per axis, drawn from rng.
  BSplineWarp(const VolumeGrid& grid, const Vec3& spacing_mm, const Vec3& max_displacement_mm, Rng& rng);

  // u at voxel (i, j, k) of the grid, in mm.
  Vec3 displacementAtVoxel(std::int64_t i, std::int64_t j, std::int64_t k) const {
    return Vec3(u_[0].atVoxel(i, j, k), u_[1].atVoxel(i, j, k), u_[2].atVoxel(i, j, k));
  }
  // u and its Jacobian ∂u_r/∂y_c (row-major) anywhere, in mm.
  Vec3 displacement(const Vec3& y, std::array<double, 9>* jacobian = nullptr) const;
  Vec3 pullback(const Vec3& y) const { return y + displacement(y); }
  // φ(x): the warped position of clean point x (Newton on y + u(y) = x).
  Vec3 forward(const Vec3& x) const;
  // Smallest det(I + ∇u) over a lattice of sample points (> 0 for an invertible warp).
  double minJacobianDeterminant(int stride) const;
  const VolumeGrid& grid() const { return grid_; }
  // The control lattice and its displacements, so users can move their own points (JSON).
  nlohmann::ordered_json describe() const;

 private:
  VolumeGrid grid_;
  std::array<BSplineField, 3> u_;
};

// The warped tree: every segment cut into pieces of at most `piece_mm`, each point moved to
// φ(x), and each piece's radius scaled by the warp's local cross-section stretch so that the
// graph describes the vessels the warped image shows. origin[s] is the clean segment of piece s.
VascularTree warpTree(const VascularTree& tree, const BSplineWarp& warp, double piece_mm, std::vector<std::int32_t>& origin);

// Trilinear sample at a continuous voxel index; the border voxel continues outside the grid.
float sampleTrilinear(const Volume<float>& v, const Vec3& index);
// Resamples a volume through the warp's pull-back (trilinear).
Volume<float> warpVolume(const Volume<float>& v, const BSplineWarp& warp);

// Resamples a label volume through the warp's pull-back (nearest voxel; 0 outside the grid).
Volume<std::uint8_t> warpLabelNearest(const Volume<std::uint8_t>& v, const BSplineWarp& warp);

// Labels of the warped image. The mask is the warped partial volume ≥ ½ plus every voxel the
// warped centrelines cross; centreline and radius are re-derived from the warped tree;
// instances are taken from the clean instances (the corner of the trilinear stencil with the
// largest weight among labelled corners), so no label value is invented.
GroundTruthVolumes warpedLabels(const Volume<float>& warped_fraction, const VascularTree& warped_tree, const std::vector<std::int32_t>& origin,
                                const Volume<std::uint32_t>& clean_instances, const BSplineWarp& warp, int centerline_connectivity = 26);

}  // namespace angiosynth
