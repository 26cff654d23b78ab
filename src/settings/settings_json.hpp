#pragma once
// The `parameters` block of a sidecar (sample.json) from the declared settings: each key with the
// value it holds, quantities as {"value", "unit": "mm"} (or Pa, Pa*s, mm^3/s, deg), choices as their word, a setting left unset as its default's words
// ("the domain's voxel"). A setting that belongs to another choice (label_threshold when the
// policy is not threshold) is left out; `table`, when given, keeps that table's settings only.
#include <nlohmann/json.hpp>

#include "core/quantity_json.hpp"
#include "settings/schema.hpp"

namespace angiosynth {

template <class Options>
nlohmann::ordered_json settingsJson(const std::vector<Setting<Options>>& settings, const Options& o, const char* table = nullptr) {
  using Json = nlohmann::ordered_json;
  Json j = Json::object();
  for (const auto& s : settings) {
    if (table && std::string(table) != s.table) continue;
    if (s.only_with.key && detail::textOf(settings, o, s.only_with.key) != s.only_with.value) continue;
    // Quantities, and angles in degrees, with their unit.
    const auto number = [&](double v) {
      if (s.quantity) return quantityJson(v, internalUnit(*s.quantity));
      return std::string(s.unit) == "deg" ? quantityJson(v, "deg") : Json(v);
    };
    const bool length = s.quantity == Dimension::Length;
    j[s.key] = std::visit(
        [&](auto member) -> Json {
          if constexpr (detail::isChoiceField<decltype(member)>) {
            return Json(member.get(o));
          } else {
            using T = std::remove_cvref_t<decltype(o.*member)>;
            const auto& v = o.*member;
            if constexpr (std::is_same_v<T, double>)
              return number(v);
            else if constexpr (std::is_same_v<T, std::optional<double>>)
              return v ? number(*v) : Json(s.fallback);
            else if constexpr (std::is_same_v<T, std::optional<bool>> || std::is_same_v<T, std::optional<int>>)
              return v ? Json(*v) : Json(s.fallback);
            else if constexpr (std::is_same_v<T, std::optional<Vec3>>) {
              if (!v) return Json(s.fallback);
              return length ? Json{{"value", {v->x, v->y, v->z}}, {"unit", "mm"}} : Json{v->x, v->y, v->z};
            } else if constexpr (std::is_same_v<T, std::vector<double>>) {
              if (v.empty()) return Json(s.fallback);
              return length || (s.range_unit && std::string(s.range_unit) == "mm") ? Json{{"value", v}, {"unit", "mm"}} : Json(v);
            } else
              return Json(v);
          }
        },
        s.field);
  }
  return j;
}

}  // namespace angiosynth
