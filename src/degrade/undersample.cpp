// Undersampling: only every factor-th phase-encoding line of k-space acquired (an accelerated
// acquisition without its parallel-imaging reconstruction), the rest left zero: the image folds
// onto itself, factor copies at field of view ÷ factor along that axis, each 1/factor as bright.
// A fully sampled band of centre_lines around k-space's centre (as autocalibration lines are)
// keeps the coarse image unfolded.
#include <cmath>
#include <utility>

#include "degrade/effect.hpp"
#include "degrade/kspace.hpp"

namespace angiosynth {
namespace {

void applyUndersample(const Drawn& p, EffectContext& ctx) {
  Volume<float>& image = ctx.state.image;
  const int axis = int(std::llround(p("axis")));
  const std::int64_t factor = std::llround(p("factor")), centre = std::llround(p("centre_lines"));
  KSpace k(image);
  const auto& d = k.dims();
  std::int64_t dropped = 0;
  k.forEachSample([&](const std::array<std::int64_t, 3>& f, std::complex<float>& v) {
    // Line f acquired when it is a multiple of the factor, or within the centre's band.
    if (f[axis] % factor != 0 && 2 * std::abs(f[axis]) >= centre) {
      v = 0;
      ++dropped;
    }
  });
  ctx.record["lines_acquired_share"] = 1 - double(dropped) / double(d[0]) / double(d[1]) / double(d[2]);
  std::move(k).toImage(image, /*magnitude=*/true);
}

}  // namespace

extern const EffectType kUndersample{
    "undersample",
    "undersampled k-space: only every factor-th line along the phase-encoding axis kept (and the centre_lines around the centre), "
    "the rest zero; the image folds into factor copies at field of view ÷ factor along that axis (magnitude image)",
    {{"axis", ParamKind::Count, 0, 2, "1", "the phase-encoding axis: 0 x, 1 y, 2 z"},
     {"factor", ParamKind::Count, 1, 64, nullptr, "acceleration: one line of every factor acquired"},
     {"centre_lines", ParamKind::Count, 0, 1e6, "0", "lines around k-space's centre acquired in full (autocalibration)"}},
    applyUndersample,
    /*moves_geometry=*/false,
    /*noise=*/false,
    /*working_bytes_per_voxel=*/kKSpaceBytesPerVoxel};

}  // namespace angiosynth
