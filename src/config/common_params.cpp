#include "config/common_params.hpp"

#include <sstream>

#include "angiosynth/templates.hpp"
#include "io/graph_formats.hpp"
#include "io/mesh_writers.hpp"
#include "io/volume_formats.hpp"

namespace angiosynth {

const std::vector<MethodParam>& commonParams() {
  static const std::string volume_formats = "any of " + volumeFormatSummary();
  static const std::string graph_formats = "any of " + graphFormatSummary() + "; GXL and DOT are always written";
  static const std::string mesh_formats = "any of " + meshFormatSummary() + ": surface.<format> each";
  static const std::vector<MethodParam> p{
      {"", "seed", "integer ≥ 0", "fresh, recorded in sample.json", "the random seed: same seed and parameters, same bytes"},
      {"curves", "tortuosity", "", "1.2", "with a [curves] table, every vessel becomes a smooth curve whose arc length over chord is this (1 … 3)"},
      {"curves", "tortuosity_sd", "", "0", "normal spread of the target between vessels (0 … 1)"},
      {"curves", "wavelength", "mm", "40 × the vessel's radius", "the curve's wavelength (or wavelength_radii, multiples of each vessel's radius)"},
      {"curves", "wavelength_radii", "", "40", "the curve's wavelength in multiples of each vessel's radius (≥ 2)"},
      {"curves", "piece_length", "mm", "1 voxel", "the longest straight piece a curve is drawn with (none shorter than an eighth of its vessel's radius)"},
      {"curves", "wall_clearance", "mm", "0 mm", "kept beyond the radius (and wall) from the domain's wall"},
      {"curves", "avoid_overlaps", "true/false", "true", "flatten a curve that would touch another vessel"},
      {"image", "enabled", "true/false", "true", "write volumes at all"},
      {"image", "voxel_size", "mm", "the domain's voxel", "the image voxel edge (`voxel` = the domain's voxels)"},
      {"image", "field_of_view", "[x, y, z] mm", "the domain's extent", "three lengths from the frame's corner"},
      {"image", "supersampling", "count", "4", "S: S³ samples per partially covered voxel (1 … 16)"},
      {"image", "centerline_connectivity", "count", "26", "26: a thin voxel curve per segment; 6: every voxel a segment passes through (face-connected)"},
      {"image", "background", "", "0", "image intensity outside vessels"},
      {"image", "vessel", "", "255", "image intensity inside vessels (image = background + (vessel − background) × partial volume)"},
      {"image", "dtype", "text", "uint8", "uint8, uint16, int16 or float32"},
      {"image", "formats", "[text]", "[\"nifti\", \"png\"]", volume_formats.c_str()},
      {"image", "graph_formats", "[text]", "[\"csv\", \"vtp\", \"swc\", \"graphml\"]", graph_formats.c_str()},
      {"image", "label_policy", "text", "binary",
       "the training label (label.nii.gz; the mask stays as it is): binary (the mask), threshold, visible, soft or ignore"},
      {"image", "label_threshold", "", "0.5", "label_policy = threshold: vessel where the partial volume is at least this (0 … 1]"},
      {"image", "visible_snr", "", "2", "label_policy = visible: vessel where the noise-free contrast is at least this many noise sigmas of the image"},
      {"image", "ignore_band", "[low, high]", "[0.25, 0.75]",
       "label_policy = ignore: vessel at partial volume >= high; nnU-Net's ignore label on (low, high) and on centreline voxels below high"},
      {"degrade", "profiles", "[text]", "[]", "degraded images to write, one image_<name> each: shipped profile names, .toml profiles or VascuSynth noise files"},
      {"output", "gxl_dialect", "text", "gxl", "gxl (GXL 1.0) or vascusynth"},
      {"mesh", "enabled", "true/false", "true", "with a [mesh] table: write the vessels' surface (one closed mesh per tree) beside the graphs"},
      {"mesh", "formats", "[text]", "[\"stl\"]", mesh_formats.c_str()},
      {"mesh", "method", "tubes/contour", "tubes",
       "tubes: each vessel's free middle (no other vessel near its wall) a tube of rings on its exact wall, the parts where vessels "
       "meet (bifurcations, round ends, vessels that touch) contoured and joined to the tubes ring to ring; contour: the whole surface "
       "contoured from the signed distance"},
      {"mesh", "junctions", "nets/tetrahedra", "nets",
       "tubes: how the parts where vessels meet are contoured: nets (surface nets, about a third of the triangles: on a uniform "
       "grid where the part's radii are alike, else on the octree, where the result is a closed manifold without "
       "self-intersections and of the union's shape; else marching tetrahedra) or tetrahedra (marching tetrahedra everywhere: "
       "manifold by construction)"},
      {"mesh", "voxel_size", "mm", "the thinnest vessel's diameter / samples_across", "the finest grid step"},
      {"mesh", "samples_across", "count", "3 (tubes), 4 (contour)",
       "grid steps across each vessel's thinnest end where it is contoured (1 … 64); thicker vessels get coarser cells"},
      {"mesh", "ring_spacing", "radii", "8; with capped ends 1.5 times the rings' vertex spacing (turned by half of it)",
       "tubes: rings at most this many radii of the vessel apart (0.1 … 100); successive rings are turned by half a vertex spacing"},
      {"mesh", "wall_thickness", "mm", "0 (no wall)",
       "a hollow wall of this thickness around each vessel's lumen (seed 004): the surface bounds the wall (outer side, lumen, a flat "
       "ring at each end, all ends open); one of wall_thickness, wall_ratio, wall_from_graph"},
      {"mesh", "wall_ratio", "share of the radius", "0 (no wall)", "a hollow wall of this share of each vessel's radius at each of its ends"},
      {"mesh", "wall_from_graph", "true/false", "false", "a hollow wall of each vessel's own thickness (wall values of an [initial] network or a graph file)"},
      {"mesh", "uniform", "true/false", "false", "every vessel at the finest step"},
      {"mesh", "on_surface", "true/false", "false", "vertices exactly on the surface (no volume restoration)"},
      {"mesh", "ends", "closed/open/capped", "closed",
       "closed: round vessel ends; open: each tree's inlet and every outlet cut by the plane through its end node, perpendicular to "
       "its vessel (one boundary loop per end); capped: those loops filled by planar caps, faces labelled (CellEntityIds/ModelFaceID "
       "1 the wall, 2 … the caps; surface_faces.csv)"},
      {"mesh", "decimate", "true/false", "false",
       "collapse edges (quadric error, volume kept) while the surface keeps its topology, its triangles do not fold or turn by more than "
       "45 degrees, no new angle falls below 15 degrees (unless one already was), and every moved vertex and new triangle stays within "
       "max_error of the vessels"},
      {"mesh", "max_error", "share of the local step", "0.1", "with decimate: the largest distance from the vessels' surface, (0, 1]"},
      {"mesh", "sliver_angle", "degrees", "10 with capped ends, else 0",
       "contoured triangles with an angle below this are repaired (an edge collapsed, a cap's edge flipped, a corner moved) under "
       "decimation's checks, as a tetrahedral mesher needs; so are those with an edge shorter than 0.35 of the local step; 0: none, [0, 30]"},
      {"mesh", "max_angle", "degrees", "90 with capped ends, else 0",
       "with the sliver repair: contoured triangles with an angle above this are improved (the long edge flipped, a corner moved) under "
       "the same checks: a tetrahedral mesher splits the edge an obtuse angle faces; 0: none, else [90, 180)"},
      {"mesh", "remesh", "true/false", "true with capped ends (without decimate), else false",
       "tubes: each contoured part remeshed isotropically to its local step (long edges split, short ones collapsed, flips, moves, "
       "under decimation's checks): the nets' right-angled triangle pairs are what TetGen's quality refinement splits"},
      {"mesh", "flow_extension", "radii", "0", "open/capped: each end prolonged straight by this many radii of its vessel before the cut (0 … 100)"},
      {"mesh", "clip_box", "[mm × 6]", "none",
       "[x0, y0, z0, x1, y1, z1]: the closed surface (closed or capped ends, or a hollow wall) clipped to this box, each side's section "
       "filled flat with a hollow wall's lumens left open (seed 004's printed block); ends outside the box are gone"},
  };
  return p;
}

namespace {

void line(std::ostream& o, const MethodParam& p) {
  o << "  ";
  if (*p.table) o << '[' << p.table << "] ";
  o << p.key;
  if (*p.unit) o << " (" << p.unit << ")";
  o << ": " << p.meaning << "; ";
  if (p.fallback) o << "default " << p.fallback << '\n';
  else o << "required\n";
}

}  // namespace

std::string parameterReference(const GrowthMethod* method) {
  std::ostringstream o;
  o << "Keys of every parameter file (quantities are strings \"<number> <unit>\"; unknown keys are errors):\n";
  for (const auto& p : commonParams()) line(o, p);
  for (const auto* m : growthMethods()) {
    if (method && method != m) continue;
    o << "\n[tree] method = \"" << m->name << "\": " << m->summary << ".\n";
    for (const auto& p : m->params) line(o, p);
  }
  return o.str();
}

std::string parameterTemplate(const GrowthMethod& method, const std::string& stem, std::string& data_file, std::string& data_content) {
  data_file.clear();
  data_content.clear();
  std::string text = exampleTemplate(method.name);
  if (std::string(method.name) == "vascusynth") {
    // The shipped example names a map of the source tree; the template brings its own: uniform
    // demand in a 100³ box.
    data_file = stem + "_demand.txt";
    data_content = "100 100 100\n0 0 0 100 100 100\n1\n";
    const std::string from = "\"../demand_maps/vascusynth_rods_100.txt\"";
    text.replace(text.find(from), from.size(), "\"" + data_file + "\"");
  }
  std::ostringstream o;
  o << text << "\n# Every key, at its default (uncomment to change; `angiosynth params " << method.name << "` explains them).\n";
  const auto block = [&](const std::vector<MethodParam>& ps) {
    std::string table = "-";
    for (const auto& p : ps) {
      if (!*p.table) continue;  // top-level keys (seed) stand at the top of the example itself
      if (table != p.table) {
        table = p.table;
        o << "#\n# [" << table << "]\n";
      }
      o << "# " << p.key << " = " << (p.fallback ? p.fallback : "(required)") << "   # " << p.meaning;
      if (*p.unit) o << " (" << p.unit << ')';
      o << '\n';
    }
  };
  block(method.params);
  block(commonParams());
  return o.str();
}

}  // namespace angiosynth
