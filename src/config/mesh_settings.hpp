#pragma once
// [mesh] and `angiosynth mesh`: the surface options, each declared once (meshSettings), with the
// rules between them (meshRules). The parameter file's reader, the command's flags, `angiosynth
// params` and the sidecar's parameters all read these declarations.
#include <optional>
#include <string>
#include <vector>

#include "settings/schema.hpp"

namespace angiosynth {

// [mesh]: the outer surface of each tree, written beside the graphs (src/mesh; `angiosynth mesh`).
struct MeshParameters {
  bool enabled = false;
  std::vector<std::string> formats{"stl"};  // names of io/mesh_writers.hpp's meshFormats()
  std::string method = "tubes";             // tubes (rings along free vessels, contoured junctions) or contour (all contoured)
  std::string junctions = "nets";           // tubes: parts contoured by surface nets where they pass their checks, or by tetrahedra only
  std::optional<double> voxel_mm;           // finest step; unset: the thinnest vessel's diameter / samples_across
  std::optional<int> samples_across;        // unset: the method's (contour 4, tubes 3)
  std::optional<double> ring_spacing;       // tubes: rings at most this many radii apart; unset: 8, with capped ends 1.5 ring vertex spacings (0)
  double ringSpacing() const { return ring_spacing ? *ring_spacing : ends == "capped" ? 0 : 8; }
  double wall_thickness = 0;           // mm: a hollow wall of this thickness (0: none), or
  double wall_ratio = 0;               // of this share of each vessel's radius, or
  bool wall_from_graph = false;        // of each vessel's own wall (a graph's wall thickness)
  bool uniform = false;                // every vessel at the finest step
  bool on_surface = false;             // no volume restoration: vertices exactly on the surface
  std::string ends = "closed";         // closed (round), open (cut at planes) or capped (planar caps, labelled faces)
  double flow_extension = 0;           // open/capped: straight extension of each end, in radii of its vessel
  bool decimate = false;               // edge-collapse decimation within max_error of the surface
  double max_error = 0.1;              // share of the local step
  std::optional<double> sliver_angle;  // degrees: contoured triangles with a smaller angle are repaired; unset: 10 with capped ends, else 0 (none)
  double sliverAngle() const { return sliver_angle ? *sliver_angle : ends == "capped" ? 10 : 0; }
  std::optional<double> max_angle;  // degrees: with the sliver repair, larger angles are improved; unset: 90 with capped ends, else 0 (none)
  double maxAngle() const { return max_angle ? *max_angle : ends == "capped" ? 90 : 0; }
  std::optional<bool> remesh;  // tubes: contoured parts remeshed isotropically; unset: with capped ends and without decimate
  bool remeshes() const { return remesh ? *remesh : ends == "capped" && !decimate; }
  // mm: x0, y0, z0, x1, y1, z1 of a box the closed surface is clipped to, each side's section
  // filled (a hollow wall's lumen open there); empty: none
  std::vector<double> clip_box;
  bool hollowWall() const { return wall_thickness > 0 || wall_ratio > 0 || wall_from_graph; }
};

// Every [mesh] setting, in the order of the reference.
const std::vector<Setting<MeshParameters>>& meshSettings();
// The rules between them (walls exclude each other and need tubes and open ends, a flow
// extension needs open ends, the clip box's corners, at least one format).
const std::vector<SettingRule<MeshParameters>>& meshRules();

// Why a max_angle given is refused, or empty: 0 (none) or an obtuse bound below 180°.
std::string maxAngleProblem(double degrees);

}  // namespace angiosynth
