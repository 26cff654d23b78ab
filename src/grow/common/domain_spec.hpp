#pragma once
// The [domain] table and a tree's root as the CCO-family methods (cco, dcco) read them: an
// analytic shape centred in its voxel frame, a NIfTI mask or a VascuSynth box map; a root given
// relative to an analytic shape's centre, or in mm or voxels for masks.
#include <cstdint>
#include <filesystem>

#include <nlohmann/json.hpp>
#include <string>

#include "domain/growth_domain.hpp"
#include "grow/method.hpp"
#include "settings/toml_reader.hpp"

namespace angiosynth {

// The [domain] of a CCO-family method: an analytic shape or a mask file.
struct DomainSpec {
  DomainShape shape = DomainShape::Sphere;
  double size_mm = 0;            // radius (sphere, disc) or side (cube, square)
  std::filesystem::path mask;    // shape mask: NIfTI (.nii, .nii.gz) or a VascuSynth box map
  bool demand_weighted = false;  // sampling = "demand": terminals drawn ∝ mask value
  double voxel_mm = 0;           // analytic shapes and box maps; a NIfTI mask carries its own
  int line = 0;                  // of [domain]
};

// Where a tree enters the domain, as the file gives it.
struct RootSpec {
  bool has_root_offset = false;  // analytic shapes: root = centre + offset (default: the top, +y)
  Vec3 root_offset_mm;
  bool root_in_mm = false;  // masks: `root` (mm in the frame) rather than root_voxel
  Vec3 root_mm;
  Vec3 root_voxel;  // masks: the root in mask voxels
  int root_line = 0;
};

// The declarations of [domain] and of a [tree] root (cco, dcco), before `rows`; `sampling`
// says what [domain] sampling does for the method.
std::vector<MethodParam> withDomainParams(const char* shape_meaning, const char* sampling_meaning, std::vector<MethodParam> rows);
// The mask file of a domain, if any: growth reads it, so outputs must not hold it.
std::vector<std::filesystem::path> domainInputs(const DomainSpec& spec);

// The [domain], [tree] and [physics] tables of a method's file (keys checked against its
// declarations), its domain read, and whether the domain is flat (disc, square).
struct MethodFileTables {
  const toml::table& domain;
  const toml::table& tree;
  const toml::table& physics;
  DomainSpec spec;
  bool flat;
};
MethodFileTables readMethodFileTables(const TomlReader& r, const GrowthMethod& m);

// [domain] of a parameter file (keys checked by the method's declarations beforehand).
DomainSpec readDomainSpec(const TomlReader& r, const toml::table& dom, const std::filesystem::path& parameter_file);
// The root of one tree from its table (`name`: "tree" or "tree.inlet"): root_offset for analytic
// shapes, root (mm) or root_voxel for masks; `required`: an analytic shape has no default root.
RootSpec readRootOf(const TomlReader& r, const toml::table& t, const std::string& name, const DomainSpec& d, bool required);
// The growth domain: the analytic shape on its voxel frame, a NIfTI mask, or a VascuSynth box
// map (whose reader checks `root` too); checks the memory before allocating.
GrowthDomain loadDomainSpec(const DomainSpec& spec, const std::string& parameter_file, const RootSpec& root, std::uint64_t memory_limit_bytes);
// A root in the domain's frame (mm): the offset from the centre for analytic shapes; must lie
// inside or on the border.
Vec3 placeRoot(const std::string& parameter_file, const RootSpec& root, const GrowthDomain& d);
// The domain and the root as sample.json records them: shape, mask or radius/side, the root,
// voxel_size.
void describeDomainAndRoot(const DomainSpec& d, const RootSpec& root, nlohmann::ordered_json& j);

}  // namespace angiosynth
