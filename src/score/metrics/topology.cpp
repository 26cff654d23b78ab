// Betti numbers of the prediction and of the truth mask.
#include <cstdlib>

#include "score/betti.hpp"
#include "score/measures.hpp"
#include "score/metric.hpp"

namespace angiosynth {

extern const ScoreMetric kTopologyMetric{
    "topology",
    "Betti numbers: b0 pieces of the foreground (26-connected), b2 cavities (6-connected background pieces not reaching the "
    "outside; the volume padded with background), b1 tunnels = b0 + b2 - the Euler characteristic of the union of closed voxel "
    "cubes; errors |prediction - truth|",
    {{"b0_error", "/b0_error"}, {"b1_error", "/b1_error"}, {"b2_error", "/b2_error"}},
    [](const ScoringCase& c) {
      using Json = nlohmann::ordered_json;
      const Betti bp = bettiNumbers(c.prediction), bt = bettiNumbers(c.truth);
      const auto json = [](const Betti& b) { return Json{{"b0", b.b0}, {"b1", b.b1}, {"b2", b.b2}, {"euler_characteristic", b.euler}}; };
      return Json{{"prediction", json(bp)},
                  {"truth", json(bt)},
                  {"b0_error", std::abs(bp.b0 - bt.b0)},
                  {"b1_error", std::abs(bp.b1 - bt.b1)},
                  {"b2_error", std::abs(bp.b2 - bt.b2)}};
    }};

}  // namespace angiosynth
