#pragma once
// A growth method as one unit: its parameters (declared once, for the reader, the defaults and
// `angiosynth methods`), the reader of its TOML tables, its description for sample.json and its
// grow function. The pipeline, the dataset engine and the command line see only this interface;
// each method lives in its own folder under src/grow/ and registers in method_registry.cpp.
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/forest.hpp"
#include "domain/demand_map.hpp"
#include "grow/common/growth_report.hpp"
#include "physics/hemodynamics.hpp"

namespace angiosynth {

class GrowthDomain;
class TomlReader;

// One key of a method's tables, as docs/methods.md and `angiosynth methods` list it.
struct MethodParam {
  const char* table;  // "domain", "tree", "physics", or a sub-table such as "tree.inlet"
  const char* key;
  const char* unit;      // "mm", "Pa", "mm^3/s", "Pa*s", "" for numbers, "text", "true/false", "[x, y, z] mm", ...
  const char* fallback;  // the default as written in a file ("3.6 mPa*s"); nullptr: required
  const char* meaning;
};

// What one task of a growth in parts did (PreparedGrowth::growPart).
struct PartTaskSummary {
  std::filesystem::path file;  // the part's file
  bool resumed = false;        // it was there already, from the same parameters and seed: kept
  std::int64_t terminals = 0;
  double seconds = 0;  // its growth (when resumed: as recorded)
};

// A method's domain read and checked, ready to grow (possibly several samples from it).
class PreparedGrowth {
 public:
  virtual ~PreparedGrowth() = default;
  // The voxel frame of the domain: the image grid, graph voxel coordinates and maps refer to it.
  virtual const DemandMap& frame() const = 0;
  // Checks, in milliseconds, that growth can succeed (root, room for the terminals and vessels).
  virtual void checkFeasibility() const = 0;
  // The analytic or mask domain, when the method grows in one (2D domains get an SVG figure).
  virtual const GrowthDomain* domain() const { return nullptr; }
  // Grows the forest for (seed, sample); throws GrowthError when the domain cannot be filled.
  virtual Forest grow(std::uint64_t seed, std::uint64_t sample, GrowthReport& report, const ProgressFn& progress) const = 0;
  // Growth in parts that separate processes grow (a cluster array's tasks) and one joins: how
  // many parts the parameters ask for, 0 when the method grows whole.
  virtual int parts() const { return 0; }
  // Grows part `index` of (seed, sample) into its file in `dir`, whole or not at all, unless the
  // file of the same parameters, seed and sample is there (a rerun task resumes).
  virtual PartTaskSummary growPart(std::uint64_t seed, std::uint64_t sample, int index, const std::filesystem::path& dir) const;
  // The forest joined from every part's file in `dir`: the one grow() makes for (seed, sample).
  // InputError naming the parts whose files are missing.
  virtual Forest joinParts(std::uint64_t seed, std::uint64_t sample, const std::filesystem::path& dir, GrowthReport& report,
                           const ProgressFn& progress) const;
  // Figures only this method reports, added to sample.json's statistics.
  virtual void addStatistics(const GrowthReport&, nlohmann::ordered_json&) const {}
};

// A method's options as read from a parameter file: immutable, shared by the samples of a run.
class GrowthSetup {
 public:
  virtual ~GrowthSetup() = default;
  virtual const char* method() const = 0;
  // The resolved parameters with their units, for sample.json (the pipeline adds image and profiles).
  virtual nlohmann::ordered_json describe() const = 0;
  // Every file growth reads (maps, masks): outputs must not hold them.
  virtual std::vector<std::filesystem::path> inputs() const = 0;
  // Reads and checks the domain files; writes nothing.
  virtual std::unique_ptr<PreparedGrowth> prepare(std::uint64_t memory_limit) const = 0;
  // The physics of the (first) tree: cost exponents for the statistics.
  virtual const PhysicsParameters& physics() const = 0;
  virtual std::int64_t terminals() const = 0;
  // The kinds of the trees it grows, each once ("artery", "vein", free names): known before
  // growth, so a dataset can check its label list against every sample.
  virtual std::vector<std::string> kinds() const = 0;
  // The voxel of the domain in mm, for lengths written in "voxel" (0 until a mask is read).
  virtual double voxelMm() const = 0;
};

struct GrowthMethod {
  const char* name;
  const char* summary;  // one line for the docs and `angiosynth methods`
  std::vector<MethodParam> params;
  // Reads [domain], [tree] and [physics] of a TOML parameter file.
  std::shared_ptr<const GrowthSetup> (*read)(const TomlReader& reader, const GrowthMethod& self);
};

// Every method, in the order the docs list them.
const std::vector<const GrowthMethod*>& growthMethods();
const GrowthMethod* findGrowthMethod(const std::string& name);
// The names, comma-separated, for errors.
std::string growthMethodNames();
// Markdown reference of every method with its parameters (`angiosynth methods`, docs/methods.md).
std::string methodReference();
// The method (other than `self`) that declares table.key, or nullptr: for "is for method X" errors.
const GrowthMethod* methodDeclaring(const std::string& table, const std::string& key, const GrowthMethod* self);

}  // namespace angiosynth
