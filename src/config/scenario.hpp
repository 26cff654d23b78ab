#pragma once
// A validated parameter set in internal units (mm, mm^3/s, Pa, Pa*s), with where every value
// came from, so that later errors (e.g. a root in zero demand) can still point at a file line.
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/units.hpp"
#include "settings/input_paths.hpp"
#include "settings/param_checks.hpp"
#include "grow/common/curved_vessels.hpp"
#include "grow/method.hpp"
#include "raster/label_policy.hpp"

namespace toml {
inline namespace v3 {
class table;
}
}  // namespace toml

namespace angiosynth {

// How the tree becomes volumes (issue: rasterizer). Defaults suit 8-bit images of the map.
struct ImageParameters {
  bool enabled = true;
  double voxel_mm = 0;                 // 0: the demand map's voxel size
  Vec3 field_of_view_mm;               // 0: the demand map's extent
  int supersampling = 4;               // S: S³ samples per partially covered voxel
  int centerline_connectivity = 26;    // of the centreline channel: 26 or 6
  double background = 0, vessel = 255; // image = background + (vessel − background) × fraction
  std::string dtype = "uint8";         // uint8, uint16, int16, float32
  std::vector<std::string> formats{"nifti", "png"};                        // names of io/volume_formats.hpp
  std::vector<std::string> graph_formats{"csv", "vtp", "swc", "graphml"};  // names of io/graph_formats.hpp; GXL and DOT always
  LabelPolicy labels;                  // the training label (label.nii.gz) beside the mask
  int labels_line = 0;
};

// [mesh]: the outer surface of each tree, written beside the graphs (src/mesh; `angiosynth mesh`).
struct MeshParameters {
  bool enabled = false;
  std::vector<std::string> formats{"stl"};  // names of io/mesh_writers.hpp's meshFormats()
  std::string method = "tubes";             // tubes (rings along free vessels, contoured junctions) or contour (all contoured)
  std::string junctions = "nets";           // tubes: parts contoured by surface nets where they pass their checks, or by tetrahedra only
  double voxel_mm = 0;                      // finest step; 0: the thinnest vessel's diameter / samples_across
  int samples_across = 0;                   // 0: the method's (contour 4, tubes 3)
  double ring_spacing = -1;                 // tubes: rings at most this many radii apart; −1: 8, with capped ends 1.5 ring vertex spacings (0)
  double ringSpacing() const { return ring_spacing > 0 ? ring_spacing : ends == "capped" ? 0 : 8; }
  double wall_thickness = 0;                // mm: a hollow wall of this thickness (0: none), or
  double wall_ratio = 0;                    // of this share of each vessel's radius, or
  bool wall_from_graph = false;             // of each vessel's own wall (a graph's wall thickness)
  bool uniform = false;                     // every vessel at the finest step
  bool on_surface = false;                  // no volume restoration: vertices exactly on the surface
  std::string ends = "closed";              // closed (round), open (cut at planes) or capped (planar caps, labelled faces)
  double flow_extension = 0;                // open/capped: straight extension of each end, in radii of its vessel
  bool decimate = false;                    // edge-collapse decimation within max_error of the surface
  double max_error = 0.1;                   // share of the local step
  double sliver_angle = -1;                 // degrees: contoured triangles with a smaller angle are repaired; −1: 10 with capped ends, else 0 (none)
  double sliverAngle() const { return sliver_angle >= 0 ? sliver_angle : ends == "capped" ? 10 : 0; }
  double max_angle = -1;                    // degrees: with the sliver repair, contoured triangles with a larger angle are improved; −1: 90 with capped ends, else 0 (none)
  double maxAngle() const { return max_angle >= 0 ? max_angle : ends == "capped" ? 90 : 0; }
  int remesh = -1;                          // tubes: contoured parts remeshed isotropically (1) or not (0); −1: with capped ends and without decimate
  bool remeshes() const { return remesh >= 0 ? remesh == 1 : ends == "capped" && !decimate; }
  // mm: x0, y0, z0, x1, y1, z1 of a box the closed surface is clipped to, each side's section
  // filled (a hollow wall's lumen open there); empty: none
  std::vector<double> clip_box;
  bool hollowWall() const { return wall_thickness > 0 || wall_ratio > 0 || wall_from_graph; }
};

// Why a max_angle given is refused, or empty: 0 (none) or an obtuse bound below 180°.
inline std::string maxAngleProblem(double degrees) {
  if (degrees == 0 || (degrees >= 90 && degrees < 180)) return {};
  return "max_angle = " + show(degrees) + " degrees is out of range; allowed: 0 (none) or [90, 180)";
}

// Why p's clip box is refused, or empty: six numbers, each lower bound below its upper one, and
// a closed surface to clip (closed or capped ends, or a hollow wall, whose ends are joined).
inline std::string clipBoxProblem(const MeshParameters& p) {
  if (p.clip_box.empty()) return {};
  if (p.clip_box.size() != 6) return "clip_box must hold 6 numbers (mm): x0, y0, z0, x1, y1, z1";
  for (double c : p.clip_box)
    if (!(std::abs(c) <= physical::kMaxCoordinateMm))
      return "clip_box corner coordinate " + show(c) + " mm is out of range; allowed: -" + show(physical::kMaxCoordinateMm) +
             " to " + show(physical::kMaxCoordinateMm) + " mm";
  for (int k = 0; k < 3; ++k)
    if (!(p.clip_box[std::size_t(k)] < p.clip_box[std::size_t(k + 3)]))
      return "clip_box's lower corner must lie below its upper one on every axis; allowed: x0 < x1, y0 < y1, z0 < z1 (mm)";
  if (p.ends == "open" && !p.hollowWall())
    return "clip_box clips a closed surface; allowed: ends \"closed\" or \"capped\", or a hollow wall";
  return {};
}

struct Scenario {
  std::string parameter_file;
  std::string format;  // "vascusynth" or "toml"
  std::shared_ptr<const GrowthSetup> growth;   // the growth method and its options
  std::optional<std::uint64_t> seed;
  CurveOptions curves;                         // [curves]: vessels made curves after growth
  int curves_line = 0;
  ImageParameters image;
  int image_line = 0;                          // line of [image], for errors about its size
  MeshParameters mesh;
  int mesh_line = 0;
  std::string gxl_dialect = "gxl";             // "gxl" (GXL 1.0) or "vascusynth"
  std::vector<std::string> profiles;           // [degrade] profiles: names or files
  int profiles_line = 0;
  CoherentUnits input_units;                   // only for VascuSynth files
  std::string units_note;
};

struct ReadOptions {
  std::string vascusynth_length_unit = "cm";   // unit of VOXEL_WIDTH in VascuSynth files
};

// Reads a VascuSynth parameter file (2008 or 2011 keys).
Scenario readVascuSynthParameters(const std::filesystem::path& file, const ReadOptions& opt = {});
// Reads a native TOML parameter file.
Scenario readTomlParameters(const std::filesystem::path& file);
// The same from a parsed table; relative paths are resolved beside `file` (a dataset spec).
Scenario readTomlParameters(const toml::table& root, const std::filesystem::path& file);
// Chooses by extension: .toml is native, anything else VascuSynth.
Scenario readParameters(const std::filesystem::path& file, const ReadOptions& opt = {});

// Every file a scenario reads (parameter file, maps, mask, profile files): outputs must not hold them.
std::vector<std::filesystem::path> scenarioInputs(const Scenario& sc);

}  // namespace angiosynth
