#pragma once
// The vessels' surface files of a tree (src/mesh through io/mesh_writers): surface.<format> per
// format and their description for sample.json or mesh.json. Shared by `generate` ([mesh]) and
// `angiosynth mesh`.
#include <cstdint>
#include <filesystem>
#include <functional>

#include <nlohmann/json.hpp>

#include "core/vascular_tree.hpp"
#include "config/scenario.hpp"

namespace angiosynth {

struct SurfaceFiles {
  nlohmann::ordered_json parameters;  // as resolved
  nlohmann::ordered_json statistics;  // counts, topology, volume, steps
  nlohmann::ordered_json files;       // format → file name
};

// Throws InputError (nothing written) when the surface would exceed the memory limit.
// `tree_kinds` (per tree, may be empty): a "vein" drains to its root, so its root end is the
// outlet and its leaves the inlets; other trees flow from the root. `vessel_ids` (per node, may
// be empty): the ids surface_faces.csv names vessels by (a graph file's own), else node ids.
SurfaceFiles writeSurfaceFiles(const VascularTree& tree, const MeshParameters& p, std::uint64_t memory_limit, const std::filesystem::path& dir,
                               const std::function<void(std::int64_t, std::int64_t)>& progress = {},
                               const std::vector<std::string>& tree_kinds = {}, const std::vector<std::string>& vessel_ids = {});

}  // namespace angiosynth
