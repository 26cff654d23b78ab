// Partial Fourier: a share of k-space's lines along the phase-encoding axis acquired, from one
// edge past the centre, the rest zero-filled (a faster acquisition without its homodyne
// reconstruction): the magnitude image loses resolution along that axis and rings at edges.
#include <cmath>
#include <utility>

#include "degrade/effect.hpp"
#include "degrade/kspace.hpp"

namespace angiosynth {
namespace {

void applyPartialFourier(const Drawn& p, EffectContext& ctx) {
  Volume<float>& image = ctx.state.image;
  const int axis = int(std::llround(p("axis")));
  KSpace k(image);
  const std::int64_t n = k.dims()[axis];
  // Lines acquired: f ≥ −(share − ½)·n, so share · n of the n lines, all the positive side.
  const std::int64_t lowest = -std::int64_t(std::floor((p("share") - 0.5) * double(n)));
  k.forEachSample([&](const std::array<std::int64_t, 3>& f, std::complex<float>& v) {
    if (f[axis] < lowest) v = 0;
  });
  ctx.record["lowest_line"] = lowest;
  std::move(k).toImage(image, /*magnitude=*/true);
}

}  // namespace

extern const EffectType kPartialFourier{
    "partial_fourier",
    "partial Fourier: only share of k-space's lines along the phase-encoding axis acquired (all of one half and a band past the centre), "
    "the rest zero (magnitude image): resolution lost along that axis only",
    {{"axis", ParamKind::Count, 0, 2, "1", "the phase-encoding axis: 0 x, 1 y, 2 z"},
     {"share", ParamKind::Probability, 0.5, 1, "0.625", "share of the lines acquired (5/8 and 6/8 are usual)"}},
    applyPartialFourier,
    /*moves_geometry=*/false,
    /*noise=*/false,
    /*working_bytes_per_voxel=*/kKSpaceBytesPerVoxel};

}  // namespace angiosynth
