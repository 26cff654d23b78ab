#pragma once
// Numbers as the JSON outputs record them: a value with its unit as sample.json records it
// ({"value": v, "unit": "mm"}), a number that may be NaN, a range that may be open.
#include <cmath>

#include <nlohmann/json.hpp>

namespace angiosynth {

inline nlohmann::ordered_json quantityJson(double value, const char* unit) { return nlohmann::ordered_json{{"value", value}, {"unit", unit}}; }

// The number, or null where it is NaN or infinite (JSON holds neither).
inline nlohmann::ordered_json numberOrNull(double v) { return std::isfinite(v) ? nlohmann::ordered_json(v) : nlohmann::ordered_json(); }

// [lower, upper], an open upper end written "inf".
inline nlohmann::ordered_json rangeJson(double lower, double upper) {
  return nlohmann::ordered_json::array({lower, std::isfinite(upper) ? nlohmann::ordered_json(upper) : nlohmann::ordered_json("inf")});
}

}  // namespace angiosynth
