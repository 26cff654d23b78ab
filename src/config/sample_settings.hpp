#pragma once
// [curves], [degrade] and [output]: the settings of a sample besides its growth, image and mesh,
// each declared once. [curves] fills CurveOptions (grow/common/curved_vessels.hpp); [degrade]
// and [output] fill the scenario itself.
#include <vector>

#include "config/scenario.hpp"
#include "settings/schema.hpp"

namespace angiosynth {

const std::vector<Setting<CurveOptions>>& curveSettings();
const std::vector<SettingRule<CurveOptions>>& curveRules();
// [degrade] profiles and [output] gxl_dialect.
const std::vector<Setting<Scenario>>& outputSettings();

}  // namespace angiosynth
