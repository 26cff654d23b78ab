#pragma once
// A 2D tree as SVG, in mm: each segment a line as wide as its diameter with round caps, over
// the outline of the domain (a circle or square; masks as their voxels). y points up, as in the
// frame, so the picture matches the image's orientation in viewers that put +y at the top.
#include <ostream>

#include "core/forest.hpp"
#include "domain/growth_domain.hpp"

namespace angiosynth {

// Each tree is drawn in its kind's colour (artery red, vein blue).
void writeSvg(std::ostream& out, const Forest& forest, const GrowthDomain& domain);

}  // namespace angiosynth
