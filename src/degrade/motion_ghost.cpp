// Motion ghosts: a periodic motion (breathing, pulsation) during the acquisition modulates the
// k-space lines along the phase-encoding axis with its period, which puts faint copies of the
// image at field of view ÷ period along that axis; the magnitude image is kept, as scanners show it.
#include <cmath>
#include <utility>
#include <numbers>

#include "degrade/effect.hpp"
#include "degrade/kspace.hpp"

namespace angiosynth {
namespace {

void applyMotionGhost(const Drawn& p, EffectContext& ctx) {
  Volume<float>& image = ctx.state.image;
  const int axis = int(std::llround(p("axis")));
  const double period = p("period"), depth = p("amplitude");
  KSpace k(image);
  const auto& d = k.dims();
  // Lines acquired from the lowest frequency to the highest, one per time step: line t's signal
  // scaled by 1 + depth × cos(2π t / period).
  k.forEachSample([&](const std::array<std::int64_t, 3>& f, std::complex<float>& v) {
    const std::int64_t t = f[axis] + d[axis] / 2;
    v *= float(1 + depth * std::cos(2 * std::numbers::pi * double(t) / period));
  });
  ctx.record["ghost_shift_voxels"] = double(d[axis]) / period;
  std::move(k).toImage(image, /*magnitude=*/true);
}

}  // namespace

extern const EffectType kMotionGhost{
    "motion_ghost",
    "motion ghosts: the k-space lines along the phase-encoding axis modulated by 1 + amplitude × cos(2π t / period) in their "
    "order of acquisition; copies of amplitude ÷ 2 of the image at ± field of view ÷ period along that axis (magnitude image)",
    {{"axis", ParamKind::Count, 0, 2, "1", "the phase-encoding axis: 0 x, 1 y, 2 z"},
     {"period", ParamKind::Number, 2, 1e6, nullptr, "lines acquired per motion cycle"},
     {"amplitude", ParamKind::Number, 0, 1, nullptr, "depth of the modulation (ghosts of half its size)"}},
    applyMotionGhost,
    /*moves_geometry=*/false,
    /*noise=*/false,
    /*working_bytes_per_voxel=*/kKSpaceBytesPerVoxel};

}  // namespace angiosynth
