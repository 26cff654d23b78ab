#include "config/common_params.hpp"

#include <sstream>

#include "angiosynth/templates.hpp"
#include "io/graph_formats.hpp"
#include "config/mesh_settings.hpp"
#include "io/volume_formats.hpp"

namespace angiosynth {

const std::vector<MethodParam>& commonParams() {
  static const std::string volume_formats = "any of " + volumeFormatSummary();
  static const std::string graph_formats = "any of " + graphFormatSummary() + "; GXL and DOT are always written";
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
  };
  // [mesh] from its declarations (config/mesh_settings.cpp).
  static const std::vector<SettingRow> mesh_rows = referenceRows(meshSettings());
  static const std::vector<MethodParam> all = [] {
    std::vector<MethodParam> out = p;
    for (const auto& r : mesh_rows) out.push_back({r.table.c_str(), r.key.c_str(), r.unit.c_str(), r.fallback.c_str(), r.meaning.c_str()});
    return out;
  }();
  return all;
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
