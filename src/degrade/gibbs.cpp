// Gibbs ringing: k-space truncated to its central part along each axis, as an MR acquisition of
// fewer phase-encoding lines or readout samples records it; a sharp edge overshoots by about 9 %
// of its step and rings with the period of the highest frequency kept.
#include <cmath>
#include <utility>

#include "degrade/effect.hpp"
#include "degrade/kspace.hpp"

namespace angiosynth {
namespace {

void applyGibbs(const Drawn& p, EffectContext& ctx) {
  Volume<float>& image = ctx.state.image;
  KSpace k(image);
  const auto& d = k.dims();
  const double keep[3] = {p("keep_x"), p("keep_y"), p("keep_z")};
  // The highest frequency kept per axis (cycles per field of view); a one-voxel axis keeps its one.
  std::int64_t limit[3];
  for (int a = 0; a < 3; ++a) limit[a] = d[a] == 1 ? 0 : std::int64_t(std::floor(keep[a] * d[a] / 2.0));
  k.forEachSample([&](const std::array<std::int64_t, 3>& f, std::complex<float>& v) {
    if (std::abs(f[0]) > limit[0] || std::abs(f[1]) > limit[1] || std::abs(f[2]) > limit[2]) v = 0;
  });
  std::move(k).toImage(image, /*magnitude=*/false);
}

}  // namespace

extern const EffectType kGibbs{
    "gibbs",
    "Gibbs ringing: k-space truncated to the central share keep_x, keep_y, keep_z of its width along each axis (the image's "
    "resolution, not its grid, reduced); edges overshoot by about 9 % of their step and ring",
    {{"keep_x", ParamKind::Probability, 0.01, 1, "1", "share of k-space's width kept along x (1: all of it)"},
     {"keep_y", ParamKind::Probability, 0.01, 1, "1", "share kept along y"},
     {"keep_z", ParamKind::Probability, 0.01, 1, "1", "share kept along z"}},
    applyGibbs,
    /*moves_geometry=*/false,
    /*noise=*/false,
    /*working_bytes_per_voxel=*/kKSpaceBytesPerVoxel};

}  // namespace angiosynth
