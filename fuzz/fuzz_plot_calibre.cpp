// Score results (JSON) as plot-calibre reads them: the curve of one case or a dataset's mean,
// then drawn.
#include <nlohmann/json.hpp>

#include "fuzz_support.hpp"
#include "score/calibre_plot.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace angiosynth;
  const auto j = nlohmann::ordered_json::parse(data, data + size, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded()) return 0;
  return fuzz::expectOnlyInputErrors([&] { plotCalibreCurves({calibreCurve(j, "scores.json")}); });
}
