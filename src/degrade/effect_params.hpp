#pragma once
// Parameters of degradation effects: what each effect declares, what a profile gives (a value
// or a range to draw from, with units), and the values drawn for one image.
//
// Amounts carry their reference so that a profile is portable across grids and intensity
// scales: lengths in mm (or "1.5 voxel", "0.25 fov": a fraction of the field of view, per axis);
// intensities as plain numbers in the image's scale, "background", "vessel", or "0.1 contrast"
// (a fraction of vessel − background).
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/rng.hpp"
#include "core/vec3.hpp"
#include "raster/volume.hpp"

namespace toml {
inline namespace v3 {
class node;
}
}  // namespace toml

namespace angiosynth {

enum class ParamKind {
  Intensity,    // image intensity units
  Length,       // mm, one value (a "voxel" or "fov" is the mean over the axes)
  Length3,      // mm per axis; one value means isotropic
  Probability,  // [0, 1]
  Count,        // whole number
  Number,       // dimensionless
};

struct Amount {
  enum class Ref { Plain, Voxel, Fov, Contrast, Background, Vessel };
  double value = 0;
  Ref ref = Ref::Plain;
};

// A value or a range (uniform, or log-uniform when `log`) of one component.
struct ParamRange {
  Amount lo, hi;
  bool range = false;
  bool log = false;
};

// What a profile gives for one parameter: one range, or one per axis for Length3.
struct ParamSpec {
  std::vector<ParamRange> components;  // 1, or 3 for a per-axis Length3
  std::string file;
  int line = 0;
};

struct ParamDecl {
  const char* name;
  ParamKind kind;
  double lo, hi;         // allowed values after resolution, closed interval
  const char* fallback;  // default, written as in a profile ("0", "vessel", "1 voxel"); nullptr: required
  const char* meaning;   // for the docs and errors
  // Lengths only: bounds relative to the image grid (0: none), per axis. A B-spline lattice finer
  // than a voxel has more control points than the image has voxels; a blur wider than the field
  // of view only costs time.
  double min_voxels = 0;
  double max_fov = 0;
};

// What the amounts are resolved against.
struct ParamScale {
  VolumeGrid grid;
  double background = 0, vessel = 255;
};

// Drawn values, resolved to mm and intensity units; scalars in .x.
struct Drawn {
  std::map<std::string, Vec3> values;
  double operator()(const std::string& name) const { return values.at(name).x; }
  Vec3 vec(const std::string& name) const { return values.at(name); }
};

// Reads a parameter of `kind` from a TOML node; throws InputError(file:line) on bad input.
ParamSpec readParamSpec(const toml::node& n, ParamKind kind, const std::string& name, const std::string& file);
// Parses one amount written as in a profile ("0.5 mm", "vessel", "2", ...).
Amount parseAmount(const std::string& text, ParamKind kind, const std::string& name, const std::string& where);

// Draws every declared parameter in declaration order (one uniform per component, drawn even
// for fixed values so that streams stay aligned when a value becomes a range), checks the
// allowed range, and records the values in `record`.
Drawn drawParams(const std::vector<ParamDecl>& decls, const std::map<std::string, ParamSpec>& given, const ParamScale& scale, Rng& rng,
                 nlohmann::ordered_json& record, const std::string& file, int line);

// One amount resolved on an axis (-1: the mean over axes).
double resolveAmount(const Amount& a, const ParamScale& s, int axis);
// A component's value for the uniform draw u: its value, or uniform (log-uniform) in its range.
double drawComponent(const ParamRange& r, double u, const ParamScale& s, int axis);
// A fixed plain value (VascuSynth noise files, code-built profiles).
ParamSpec fixedParam(double value, const std::string& file = "", int line = 0);

// "a value", "a range" etc. as the docs write it.
std::string describeKind(ParamKind kind);

}  // namespace angiosynth
