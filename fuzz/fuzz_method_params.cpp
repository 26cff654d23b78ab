// Each growth method's parameters, grown: the first byte picks a method, the rest is a TOML
// fragment whose keys replace those of a small template of that method (a [[stage]] fragment
// merges into the first stage). Sizes are capped (terminals, iterations, steps, drains, a DCCO
// stage's failed draws) so a
// case stays small; every other value goes to the reader and the growth as a user wrote it.
#include <toml++/toml.h>

#include <sstream>

#include "fuzz_sample.hpp"

namespace {

std::string templateOf(int method, const std::string& map) {
  const std::string disc = "seed = 1\n[domain]\nshape = \"disc\"\nradius = \"10 mm\"\nvoxel_size = \"0.1 mm\"\n";
  switch (method) {
    case 0:
      return "seed = 1\n[domain]\ndemand_map = \"" + map +
             "\"\nvoxel_size = \"1 mm\"\n[tree]\nterminals = 24\nroot_voxel = [0, 8, 8]\n"
             "[physics]\nviscosity = \"3.6 mPa*s\"\nperfusion_pressure = \"13300 Pa\"\nterminal_pressure = \"8300 Pa\"\n"
             "perfusion_flow = \"100 mm3/s\"\n";
    case 1: return disc + "[tree]\nmethod = \"cco\"\nterminals = 30\n[physics]\nperfusion_flow = \"5 mL/min\"\n";
    case 2:
      return disc +
             "[tree]\nmethod = \"dcco\"\nroot_radius = \"0.2 mm\"\n[physics]\nperfusion_flow = \"0.3 mL/min\"\n[[stage]]\nterminals = "
             "20\ndraws_before_relaxing = 20\n";
    case 3: return disc + "[tree]\nmethod = \"colonisation\"\n[[stage]]\nsteps = 10\ndrains_per_step = 200\n";
    default: return disc + "[tree]\nmethod = \"lsystem\"\nmode = \"grammar\"\niterations = 5\n";
  }
}

// Caps a count the fragment set, whatever else it is.
void cap(toml::table& t, const char* key, std::int64_t most) {
  if (auto* v = t.get(key); v && v->is_integer() && v->as_integer()->get() > most) *v->as_integer() = most;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace angiosynth;
  if (size == 0) return 0;
  const auto map = fuzz::scratchDir() / "method_map16.txt";
  static const bool written = [&] { return bool(std::ofstream(map) << "16 16 16\n0 0 0 16 16 16\n1\n"); }();
  (void)written;
  toml::table base = toml::parse(templateOf(data[0] % 5, map.string()));
  toml::table fragment;
  try {
    fragment = toml::parse(std::string_view(reinterpret_cast<const char*>(data + 1), size - 1));
  } catch (const toml::parse_error&) {
    return 0;  // the TOML reader itself is fuzz_toml_params' target
  }
  for (auto&& [name, value] : fragment) {
    if (name == "mesh" || name == "degrade" || name == "image") continue;
    auto* into = base.get(name);
    if (value.is_table() && into && into->is_table()) {
      for (auto&& [k, v] : *value.as_table()) into->as_table()->insert_or_assign(k, v);
    } else if (value.is_array_of_tables() && into && into->is_array_of_tables()) {
      auto& first = *into->as_array()->get(0)->as_table();
      for (auto&& [k, v] : *value.as_array()->get(0)->as_table()) first.insert_or_assign(k, v);
    } else {
      base.insert_or_assign(name, value);
    }
  }
  if (auto* tree = base.get_as<toml::table>("tree")) {
    cap(*tree, "terminals", 40);
    cap(*tree, "iterations", 7);
  }
  if (auto* stages = base.get_as<toml::array>("stage")) {
    while (stages->size() > 2) stages->pop_back();
    for (auto& s : *stages)
      if (auto* st = s.as_table()) {
        cap(*st, "terminals", 30);
        cap(*st, "steps", 20);
        cap(*st, "drains_per_step", 300);
        cap(*st, "draws_before_relaxing", 20);  // a stage gives up after 100 of these: 2,000 failed points, not 10,000
      }
  }
  base.insert_or_assign("image", toml::table{{"formats", toml::array{}}, {"graph_formats", toml::array{}}});
  const auto params = fuzz::scratchDir() / "method.toml";
  std::ofstream(params) << base;
  const auto out = fuzz::scratchDir() / "method";
  return fuzz::expectOnlyInputErrors([&] { fuzz::growParameterFile(params, out); });
}
