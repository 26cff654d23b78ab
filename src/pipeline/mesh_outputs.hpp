#pragma once
// The vessels' surface files of a tree (src/mesh through io/mesh_writers): surface.<format> per
// format and their description for sample.json or mesh.json. Shared by `generate` ([mesh]) and
// `angiosynth mesh`.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>

#include <nlohmann/json.hpp>

#include "core/vascular_tree.hpp"
#include "config/scenario.hpp"
#include "mesh/box_clip.hpp"
#include "mesh/vessel_surface.hpp"

namespace angiosynth {

// What the surface stage made: counts, steps, topology, volume, and each phase's work. The
// fields of one method only are unset for the other (null in JSON).
struct SurfaceSummary {
  std::int64_t trees = 0, segments = 0, vertices = 0, triangles = 0;
  double finest_step_mm = 0;
  struct Contour {  // method contour: the octree
    double coarsest_cell_mm = 0;
    int levels = 0;
    std::int64_t cells = 0;
    double largest_volume_move_mm = 0;
  };
  std::optional<Contour> contour;
  struct Tubes {  // method tubes: tubes and the contoured parts where vessels meet
    std::int64_t tubes = 0, contoured_parts = 0, parts_by_nets = 0, largest_contoured_part_vessels = 0;
    std::int64_t tube_triangles = 0, contoured_triangles = 0, given_up = 0, cuts_retried = 0;
  };
  std::optional<Tubes> tube;
  std::optional<std::int64_t> wall_ends_joined;  // a hollow wall
  double estimated_bytes = 0;
  MeshTopology topology;
  std::int64_t cavities_removed = 0;
  std::optional<std::int64_t> triangles_before_decimation;  // with decimation
  std::int64_t decimation_collapses = 0;
  double decimation_largest_error_mm = 0;
  std::int64_t sliver_repair_changes = 0, remesh_splits = 0, remesh_changes = 0;
  double smallest_angle_deg = 0;                  // of the final triangles
  std::int64_t triangles_below_sliver_angle = 0;  // with a sliver repair: what it left
  std::int64_t ends = 0, ends_cut = 0, ends_left_closed = 0, ends_extension_shortened = 0;
  std::optional<BoxClipReport> clip;  // with a clip box
  // Per tree, the Euler characteristic its vessel graph implies: 2 for one closed surface, less one
  // per open end (unknown, empty, for hollow walls and clipped surfaces). A surface of another
  // one has a handle where vessels fuse, or has fallen apart.
  std::vector<std::int64_t> tree_euler_expected;
  // What a user must know before using the surface: each end left closed or extension
  // shortened, each tree of another topology than its graph's, with the vessels that cause it.
  std::vector<std::string> warnings;
  // As sample.json's statistics.surface and mesh.json's statistics record it.
  nlohmann::ordered_json toJson() const;
};

struct SurfaceFiles {
  nlohmann::ordered_json parameters;  // the settings as the meshers took them (defaults resolved)
  SurfaceSummary statistics;
  nlohmann::ordered_json files;  // format → file name
};

// Throws InputError (nothing written) when the surface would exceed the memory limit.
// `tree_kinds` (per tree, may be empty): a "vein" drains to its root, so its root end is the
// outlet and its leaves the inlets; other trees flow from the root. `vessel_ids` (per node, may
// be empty): the ids surface_faces.csv names vessels by (a graph file's own), else node ids.
SurfaceFiles writeSurfaceFiles(const VascularTree& tree, const MeshParameters& p, std::uint64_t memory_limit, const std::filesystem::path& dir,
                               const std::function<void(std::int64_t, std::int64_t)>& progress = {}, const std::vector<std::string>& tree_kinds = {},
                               const std::vector<std::string>& vessel_ids = {});

}  // namespace angiosynth
