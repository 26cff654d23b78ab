#pragma once
// A value with its unit as sample.json records it: {"value": v, "unit": "mm"}.
#include <nlohmann/json.hpp>

namespace angiosynth {

inline nlohmann::ordered_json quantityJson(double value, const char* unit) { return nlohmann::ordered_json{{"value", value}, {"unit", unit}}; }

}  // namespace angiosynth
