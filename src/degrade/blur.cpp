// Gaussian blur with an anisotropic point-spread function (σ per axis, in mm), separable: three
// 1-D passes whose inner loops run along contiguous rows. Edges replicate the border voxel.
#include "degrade/blur.hpp"

#include <cmath>

#include <tbb/parallel_for.h>

namespace angiosynth {

std::vector<float> gaussianKernel(double sigma_voxels, double truncate) {
  if (!(sigma_voxels > 0)) return {1.0f};
  const int r = std::max(1, static_cast<int>(std::ceil(truncate * sigma_voxels)));
  std::vector<double> w(2 * r + 1);
  double sum = 0;
  for (int t = -r; t <= r; ++t) sum += w[t + r] = std::exp(-0.5 * t * t / (sigma_voxels * sigma_voxels));
  std::vector<float> out(w.size());
  for (std::size_t i = 0; i < w.size(); ++i) out[i] = static_cast<float>(w[i] / sum);
  return out;
}

namespace {

// One pass along `axis`: dst = src ⊛ kernel.
void convolveAxis(const Volume<float>& src, Volume<float>& dst, int axis, const std::vector<float>& k) {
  const auto& d = src.grid.dims;
  const int r = static_cast<int>(k.size() / 2);
  const std::int64_t nx = d[0], ny = d[1], nz = d[2];
  if (axis == 0) {
    tbb::parallel_for(std::int64_t(0), ny * nz, [&](std::int64_t row) {
      thread_local std::vector<float> pad;
      pad.resize(nx + 2 * r);
      const float* in = src.data.data() + row * nx;
      for (std::int64_t i = 0; i < nx + 2 * r; ++i) pad[i] = in[std::clamp<std::int64_t>(i - r, 0, nx - 1)];
      float* out = dst.data.data() + row * nx;
      // Tap by tap over the whole row: the inner loop is contiguous and vectorises.
      std::fill(out, out + nx, 0.0f);
      for (int t = 0; t <= 2 * r; ++t) {
        const float w = k[t];
        const float* in_t = pad.data() + t;
        for (std::int64_t i = 0; i < nx; ++i) out[i] += w * in_t[i];
      }
    });
    return;
  }
  // Along y or z: whole rows at a time, so the inner loop is contiguous and vectorises.
  const std::int64_t n_along = axis == 1 ? ny : nz;
  const std::int64_t stride = axis == 1 ? nx : nx * ny;
  tbb::parallel_for(std::int64_t(0), ny * nz, [&](std::int64_t row) {
    const std::int64_t j = row % ny, kk = row / ny;
    const std::int64_t pos = axis == 1 ? j : kk;
    const std::int64_t base = row * nx - pos * stride;  // the same row at position 0 along the axis
    float* out = dst.data.data() + row * nx;
    std::fill(out, out + nx, 0.0f);
    for (int t = -r; t <= r; ++t) {
      const std::int64_t q = std::clamp<std::int64_t>(pos + t, 0, n_along - 1);
      const float* in = src.data.data() + base + q * stride;
      const float w = k[t + r];
      for (std::int64_t i = 0; i < nx; ++i) out[i] += w * in[i];
    }
  });
}

}  // namespace

void gaussianBlur(Volume<float>& v, const Vec3& sigma_mm, double truncate, Volume<float>* scratch) {
  Volume<float> own;
  if (!scratch) own = Volume<float>(v.grid);
  Volume<float>& tmp = scratch ? *scratch : own;
  for (int ax = 0; ax < 3; ++ax) {
    const auto k = gaussianKernel(sigma_mm[ax] / v.grid.spacing_mm[ax], truncate);
    if (k.size() == 1 || v.grid.dims[ax] == 1) continue;
    convolveAxis(v, tmp, ax, k);
    std::swap(v.data, tmp.data);
  }
}

namespace {

void applyBlur(const Drawn& p, EffectContext& ctx) { gaussianBlur(ctx.state.image, p.vec("sigma"), p("truncate")); }

}  // namespace

extern const EffectType kBlur{
    "blur",
    "Gaussian point-spread function, σ per axis (separable; edges replicate the border)",
    {{"sigma", ParamKind::Length3, 0, 1e6, nullptr, "PSF standard deviation per axis (FWHM = 2.355 σ); at most the field of view", 0, 1},
     {"truncate", ParamKind::Number, 1, 10, "4", "kernel half-width in units of σ"}},
    applyBlur};

}  // namespace angiosynth
