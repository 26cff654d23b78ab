// Optical coherence tomography angiography: flowing blood scatters light, so the decorrelation
// signal of a vessel repeats below it along the beam (projection tails), and the vessel absorbs
// light the tissue under it then lacks (shadows), as Wittmann et al. (2024) simulate for OCTA.
#include <cmath>

#include <tbb/parallel_for.h>

#include "degrade/effect.hpp"

namespace angiosynth {
namespace {

void applyProjection(const Drawn& p, EffectContext& ctx) {
  auto& s = ctx.state;
  const int axis = static_cast<int>(std::llround(p("axis")));
  const double tail = p("tail"), length = p("tail_length"), absorption = p("shadow_length") > 0 ? 1 / p("shadow_length") : 0;
  const auto& d = s.grid.dims;
  const double step = s.grid.spacing_mm[axis];
  const float decay = static_cast<float>(std::exp(-step / length));
  const double contrast = s.vessel - s.background;
  // Columns along the beam are independent; each is walked from the surface (index 0) down.
  const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
  tbb::parallel_for(std::int64_t(0), std::int64_t(d[a1]) * d[a2], [&](std::int64_t column) {
    std::int64_t idx[3];
    idx[a1] = column % d[a1];
    idx[a2] = column / d[a1];
    double echo = 0, depth = 0;  // the tail carried down, the vessel path crossed above (mm)
    for (std::int64_t z = 0; z < d[axis]; ++z) {
      idx[axis] = z;
      const std::int64_t v = s.grid.flat(idx[0], idx[1], idx[2]);
      const double f = s.fraction->data[v];
      s.image.data[v] = static_cast<float>(s.image.data[v] * std::exp(-absorption * depth) + tail * contrast * echo);
      // Every vessel above, each fading with its distance: Σ f(z′)·exp(−(z − z′)·step/length).
      echo = (echo + f) * decay;
      depth += f * step;
    }
  });
}

}  // namespace

extern const EffectType kProjection{
    "projection",
    "OCTA projection artefacts along the beam (axis, surface at index 0): each vessel's signal repeats below it as a tail "
    "tail × contrast × exp(−distance/tail_length) and everything below it is darkened by exp(−vessel path above / shadow_length)",
    {{"axis", ParamKind::Count, 0, 2, "2", "the beam's axis: 0 x, 1 y, 2 z (depth grows with the index)"},
     {"tail", ParamKind::Number, 0, 10, "0.3", "the tail's strength just below a vessel, as a share of the vessel's contrast"},
     {"tail_length", ParamKind::Length, 1e-9, 1e12, "5 voxel", "distance over which a tail falls by e"},
     {"shadow_length", ParamKind::Length, 0, 1e12, "0", "vessel path over which the light below falls by e (0: no shadow)"}},
    applyProjection};

}  // namespace angiosynth
