// VascuSynth's parameter files: `KEY: value` lines, 2011 keys plus the 2008 ROW/MEW, CRLF or
// LF, with or without a space after the colon, blank lines anywhere. Lengths are in the unit of
// VOXEL_WIDTH (cm by default); flows, pressures and viscosity are taken in the coherent
// (length, g, s) system that makes VascuSynth's numbers physical (CGS for cm).
#include <map>
#include <set>

#include "core/error.hpp"
#include "settings/param_checks.hpp"
#include "grow/vascusynth/setup.hpp"
#include "config/scenario.hpp"
#include "files/text_lines.hpp"

namespace angiosynth {
namespace {

const std::vector<std::string> kKeys{
    "SUPPLY_MAP", "OXYGENATION_MAP", "RANDOM_SEED", "PERF_POINT",   "PERF_PRESSURE", "TERM_PRESSURE", "PERF_FLOW",         "RHO",
    "GAMMA",      "LAMBDA",          "MU",          "MIN_DISTANCE", "NUM_NODES",     "VOXEL_WIDTH",   "CLOSEST_NEIGHBOURS"};

std::string canonical(const std::string& key) {
  if (key == "ROW") return "RHO";
  if (key == "MEW") return "MU";
  return key;
}

std::string joined(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& k : v) s += (s.empty() ? "" : ", ") + k;
  return s;
}

}  // namespace

Scenario readVascuSynthParameters(const std::filesystem::path& path, const ReadOptions& opt) {
  const std::string file = path.string();
  struct Entry {
    std::string value;
    int line;
  };
  std::map<std::string, Entry> entries;
  for (const auto& [line, text] : readTextLines(path, "parameter")) {
    const auto colon = text.find(':');
    if (colon == std::string::npos) throw InputError(file, line, "expected 'KEY: value', got '" + text + "'; keys: " + joined(kKeys));
    const std::string key = canonical(trimmed(text.substr(0, colon)));
    const std::string value = trimmed(text.substr(colon + 1));
    if (std::find(kKeys.begin(), kKeys.end(), key) == kKeys.end())
      throw InputError(file, line,
                       "unknown key '" + trimmed(text.substr(0, colon)) + "'; allowed: " + joined(kKeys) + " (ROW and MEW are read as RHO and MU)");
    if (const auto it = entries.find(key); it != entries.end())
      throw InputError(file, line, key + " is given twice (first on line " + std::to_string(it->second.line) + "); give each key once");
    if (value.empty()) throw InputError(file, line, key + " has no value");
    entries[key] = {value, line};
  }
  std::vector<std::string> missing;
  for (const auto& k : kKeys)
    if (k != "RANDOM_SEED" && !entries.count(k)) missing.push_back(k);
  if (!missing.empty()) throw InputError(file, 0, "missing keys: " + joined(missing) + "; every key but RANDOM_SEED is required");

  const auto where = [&](const std::string& k) { return Where{file, entries.at(k).line}; };
  const auto number = [&](const std::string& k) {
    const auto words = splitWords(entries.at(k).value);
    if (words.size() != 1) throw InputError(file, entries.at(k).line, k + " takes one number, got '" + entries.at(k).value + "'");
    return parseNumber(words[0], file, entries.at(k).line, k);
  };
  const auto integer = [&](const std::string& k) {
    const auto words = splitWords(entries.at(k).value);
    if (words.size() != 1) throw InputError(file, entries.at(k).line, k + " takes one whole number, got '" + entries.at(k).value + "'");
    return parseInteger(words[0], file, entries.at(k).line, k);
  };

  Scenario sc;
  sc.parameter_file = file;
  sc.format = "vascusynth";
  CoherentUnits& u = sc.input_units;
  try {
    u.length = opt.vascusynth_length_unit;
    u.mm_per_length = lengthUnitInMm(u.length);
  } catch (const std::invalid_argument& e) { throw InputError("--vascusynth-unit", 0, e.what()); }

  const double voxel = number("VOXEL_WIDTH");
  checkRange(voxel, Limits::kMinVoxel / u.mm_per_length, false, Limits::kMaxVoxel / u.mm_per_length, false, where("VOXEL_WIDTH"),
             "VOXEL_WIDTH (" + u.length + ")");
  auto setup = std::make_shared<VascuSynthSetup>();
  BoxMapSpec& d = setup->domain;
  d.parameter_file = file;
  d.voxel_mm = voxel * u.mm_per_length;

  const auto pp = splitWords(entries.at("PERF_POINT").value);
  if (pp.size() != 3)
    throw InputError(file, entries.at("PERF_POINT").line, "PERF_POINT takes 3 numbers (map voxels), got '" + entries.at("PERF_POINT").value + "'");
  d.root_voxel = Vec3(parseNumber(pp[0], file, entries.at("PERF_POINT").line, "PERF_POINT"),
                      parseNumber(pp[1], file, entries.at("PERF_POINT").line, "PERF_POINT"),
                      parseNumber(pp[2], file, entries.at("PERF_POINT").line, "PERF_POINT"));
  d.root_line = entries.at("PERF_POINT").line;

  const double p_perf = number("PERF_PRESSURE"), p_term = number("TERM_PRESSURE");
  const double pa = u.pa_per_pressure();
  checkRange(p_term, 0, false, Limits::kMaxPressure / pa, false, where("TERM_PRESSURE"), "TERM_PRESSURE (" + u.pressureName() + ")");
  checkRange(p_perf, 0, false, Limits::kMaxPressure / pa, false, where("PERF_PRESSURE"), "PERF_PRESSURE (" + u.pressureName() + ")");
  if (!((p_perf - p_term) * pa >= Limits::kMinPressureDrop))
    throw InputError(file, entries.at("PERF_PRESSURE").line, "PERF_PRESSURE = " + show(p_perf) + " must exceed TERM_PRESSURE = " + show(p_term));
  const double flow = number("PERF_FLOW"), rho = number("RHO");
  checkRange(flow, Limits::kMinFlow / u.mm3s_per_flow(), false, Limits::kMaxFlow / u.mm3s_per_flow(), false, where("PERF_FLOW"),
             "PERF_FLOW (" + u.flowName() + ")");
  checkRange(rho, Limits::kMinViscosity / u.pas_per_viscosity(), false, Limits::kMaxViscosity / u.pas_per_viscosity(), false, where("RHO"),
             "RHO (" + u.viscosityName() + ")");
  const double gamma = number("GAMMA"), lambda = number("LAMBDA"), mu = number("MU");
  checkRange(gamma, Limits::kMinMurray, true, Limits::kMaxMurray, false, where("GAMMA"), "GAMMA");
  checkRange(lambda, 0, false, Limits::kMaxCostExponent, false, where("LAMBDA"), "LAMBDA");
  checkRange(mu, 0, false, Limits::kMaxCostExponent, false, where("MU"), "MU");
  const double min_dist = number("MIN_DISTANCE");
  checkRange(min_dist, 0, false, Limits::kMaxVoxelsPerAxis, false, where("MIN_DISTANCE"), "MIN_DISTANCE (map voxels)");
  const auto n = integer("NUM_NODES");
  checkRange(double(n), 1, false, Limits::kMaxTerminals, false, where("NUM_NODES"), "NUM_NODES");
  const auto k = integer("CLOSEST_NEIGHBOURS");
  checkRange(double(k), 1, false, Limits::kMaxNeighbours, false, where("CLOSEST_NEIGHBOURS"), "CLOSEST_NEIGHBOURS");
  if (entries.count("RANDOM_SEED")) {
    const auto seed = integer("RANDOM_SEED");
    if (seed > 0) sc.seed = static_cast<std::uint64_t>(seed);  // 0 or negative: a new tree every run
  }

  d.demand_map = resolveInputPath(entries.at("OXYGENATION_MAP").value, path, entries.at("OXYGENATION_MAP").line);
  d.supply_map = resolveInputPath(entries.at("SUPPLY_MAP").value, path, entries.at("SUPPLY_MAP").line);
  d.supply_line = entries.at("SUPPLY_MAP").line;

  auto& g = setup->growth;
  setup->terminals_line = entries.at("NUM_NODES").line;
  g.terminals = n;
  g.closest_neighbours = static_cast<int>(k);
  if (opt.vascusynth_rules) g.useVascuSynthRules();
  g.min_distance_mm = min_dist * d.voxel_mm;
  g.min_segment_length_mm = g.minSegmentLength(d.voxel_mm);  // the default (voxel / 20), recorded in the sidecar
  g.physics.murray_exponent = gamma;
  g.physics.cost_radius_exponent = lambda;
  g.physics.cost_length_exponent = mu;
  g.physics.viscosity = rho * u.pas_per_viscosity();
  g.physics.perfusion_pressure = p_perf * u.pa_per_pressure();
  g.physics.terminal_pressure = p_term * u.pa_per_pressure();
  g.physics.perfusion_flow = flow * u.mm3s_per_flow();
  g.physics.total_terminals = n;
  sc.growth = std::move(setup);

  sc.units_note = "VascuSynth files carry no units: lengths (VOXEL_WIDTH, radii) were read in " + u.length + ", flows in " + u.flowName() +
                  ", pressures in " + u.pressureName() + " and viscosity in " + u.viscosityName() + " (the coherent length-gram-second system" +
                  (u.length == "cm" ? ", i.e. CGS: dyn/cm^2 and poise" : "") +
                  "), then converted to mm, mm^3/s, Pa and Pa*s; MIN_DISTANCE and PERF_POINT are in map voxels";
  return sc;
}

}  // namespace angiosynth
