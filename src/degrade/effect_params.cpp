#include "degrade/effect_params.hpp"

#include <toml++/toml.h>

#include <cmath>
#include <sstream>

#include "core/error.hpp"
#include "core/units.hpp"
#include "settings/param_checks.hpp"

namespace angiosynth {
namespace {

int lineOf(const toml::node& n) { return static_cast<int>(n.source().begin.line); }

bool isLength(ParamKind k) { return k == ParamKind::Length || k == ParamKind::Length3; }

Amount amountOf(const toml::node& n, ParamKind kind, const std::string& name, const std::string& file) {
  const std::string where = file + ":" + std::to_string(lineOf(n));
  // Finite and within ±1e12 in its own unit: no product of such values overflows later.
  const auto bounded = [&](const Amount& a) {
    if (!(std::abs(a.value) <= 1e12))
      throw InputError(file, lineOf(n), name + " = " + show(a.value) + " is out of range; allowed: finite values within ±1e12");
    return a;
  };
  if (const auto s = n.value_exact<std::string>()) {
    try {
      return bounded(parseAmount(*s, kind, name, where));
    } catch (const std::invalid_argument& e) { throw InputError(file, lineOf(n), e.what()); }
  }
  if (n.is_number()) {
    Amount a;
    a.value = *n.value<double>();
    if (kind == ParamKind::Count && !n.is_integer()) throw InputError(file, lineOf(n), name + " must be a whole number");
    return bounded(a);
  }
  throw InputError(file, lineOf(n), name + " must be " + describeKind(kind) + ", or a range {min = …, max = …}");
}

ParamRange rangeOf(const toml::node& n, ParamKind kind, const std::string& name, const std::string& file) {
  ParamRange r;
  if (const auto* t = n.as_table()) {
    for (const auto& [k, v] : *t)
      if (k != "min" && k != "max" && k != "log")
        throw InputError(file, lineOf(v), "unknown key '" + std::string(k.str()) + "' in the range of " + name + "; allowed: min, max, log");
    const auto* lo = t->get("min");
    const auto* hi = t->get("max");
    if (!lo || !hi) throw InputError(file, lineOf(n), "the range of " + name + " needs both min and max");
    r.lo = amountOf(*lo, kind, name, file);
    r.hi = amountOf(*hi, kind, name, file);
    r.range = true;
    if (const auto* l = t->get("log")) {
      if (!l->is_boolean()) throw InputError(file, lineOf(*l), "log must be true or false");
      r.log = *l->value<bool>();
    }
    if (r.lo.ref == r.hi.ref && r.lo.value > r.hi.value) throw InputError(file, lineOf(n), "the range of " + name + " has min > max");
    if (r.log && !(r.lo.value > 0 && r.hi.value > 0))
      throw InputError(file, lineOf(n), "a log-uniform range of " + name + " needs min > 0 and max > 0");
    return r;
  }
  r.lo = r.hi = amountOf(n, kind, name, file);
  return r;
}

}  // namespace

std::string describeKind(ParamKind kind) {
  switch (kind) {
    case ParamKind::Intensity: return "an intensity (a number, \"background\", \"vessel\" or \"<x> contrast\")";
    case ParamKind::Length: return "a length (\"<x> mm\", \"<x> voxel\" or \"<x> fov\"; a bare number is mm)";
    case ParamKind::Length3: return "a length or 3 lengths, one per axis (\"<x> mm\", \"<x> voxel\", \"<x> fov\")";
    case ParamKind::Probability: return "a probability in [0, 1]";
    case ParamKind::Count: return "a whole number";
    case ParamKind::Number: return "a number";
  }
  return "";
}

Amount parseAmount(const std::string& text, ParamKind kind, const std::string& name, const std::string& where) {
  Amount a;
  if (kind == ParamKind::Intensity && (text == "background" || text == "vessel")) {
    a.ref = text == "background" ? Amount::Ref::Background : Amount::Ref::Vessel;
    return a;
  }
  std::istringstream in(text);
  std::string unit, rest;
  if (!(in >> a.value)) throw std::invalid_argument(name + " = \"" + text + "\" is not " + describeKind(kind));
  in >> unit;
  if (in >> rest) throw std::invalid_argument(name + " = \"" + text + "\": write \"<number> <unit>\"");
  if (unit.empty()) return a;
  if (isLength(kind)) {
    if (unit == "voxel" || unit == "voxels")
      a.ref = Amount::Ref::Voxel;
    else if (unit == "fov")
      a.ref = Amount::Ref::Fov;
    else
      a.value *= lengthUnitInMm(unit);  // throws with the allowed units
    return a;
  }
  if (kind == ParamKind::Intensity && unit == "contrast") {
    a.ref = Amount::Ref::Contrast;
    return a;
  }
  throw std::invalid_argument(name + " = \"" + text + "\": unit '" + unit + "' is not allowed; " + name + " is " + describeKind(kind));
}

ParamSpec readParamSpec(const toml::node& n, ParamKind kind, const std::string& name, const std::string& file) {
  ParamSpec s;
  s.file = file;
  s.line = lineOf(n);
  if (const auto* arr = n.as_array()) {
    if (kind != ParamKind::Length3 || arr->size() != 3) throw InputError(file, lineOf(n), name + " must be " + describeKind(kind));
    for (const auto& e : *arr) s.components.push_back(rangeOf(e, kind, name, file));
    return s;
  }
  s.components.push_back(rangeOf(n, kind, name, file));
  return s;
}

double resolveAmount(const Amount& a, const ParamScale& s, int axis) {
  const auto mean = [](const Vec3& v) { return (v.x + v.y + v.z) / 3; };
  const Vec3 extent(s.grid.dims[0] * s.grid.spacing_mm.x, s.grid.dims[1] * s.grid.spacing_mm.y, s.grid.dims[2] * s.grid.spacing_mm.z);
  switch (a.ref) {
    case Amount::Ref::Plain: return a.value;
    case Amount::Ref::Voxel: return a.value * (axis < 0 ? mean(s.grid.spacing_mm) : s.grid.spacing_mm[axis]);
    case Amount::Ref::Fov: return a.value * (axis < 0 ? mean(extent) : extent[axis]);
    case Amount::Ref::Contrast: return a.value * (s.vessel - s.background);
    case Amount::Ref::Background: return s.background;
    case Amount::Ref::Vessel: return s.vessel;
  }
  return a.value;
}

double drawComponent(const ParamRange& r, double u, const ParamScale& s, int axis) {
  const double lo = resolveAmount(r.lo, s, axis);
  if (!r.range) return lo;
  const double hi = resolveAmount(r.hi, s, axis);
  return r.log ? std::exp(std::log(lo) + u * (std::log(hi) - std::log(lo))) : lo + u * (hi - lo);
}

ParamSpec fixedParam(double value, const std::string& file, int line) {
  ParamSpec s;
  s.file = file;
  s.line = line;
  ParamRange r;
  r.lo.value = r.hi.value = value;
  s.components.push_back(r);
  return s;
}

namespace {

void checkGridBounds(const ParamDecl& decl, double x, const VolumeGrid& g, int axis, const Where& w) {
  if (decl.min_voxels <= 0 && decl.max_fov <= 0) return;
  const auto& s = g.spacing_mm;
  const double voxel = axis >= 0 ? s[axis] : (s.x + s.y + s.z) / 3;
  const double fov = axis >= 0 ? g.dims[axis] * s[axis] : (g.dims[0] * s.x + g.dims[1] * s.y + g.dims[2] * s.z) / 3;
  if (decl.min_voxels > 0 && x < decl.min_voxels * voxel)
    throw InputError(w.file, w.line,
                     std::string(decl.name) + " = " + show(x) + " mm is finer than " + show(decl.min_voxels) + " voxel (" + show(voxel) +
                         " mm) of this image; allowed: >= " + show(decl.min_voxels) +
                         " voxel (a finer lattice holds more control points than the image has voxels)");
  if (decl.max_fov > 0 && x > decl.max_fov * fov)
    throw InputError(w.file, w.line,
                     std::string(decl.name) + " = " + show(x) + " mm exceeds " + show(decl.max_fov) + " fov (" + show(decl.max_fov * fov) +
                         " mm) of this image; allowed: <= " + show(decl.max_fov) + " fov");
}

}  // namespace

Drawn drawParams(const std::vector<ParamDecl>& decls, const std::map<std::string, ParamSpec>& given, const ParamScale& scale, Rng& rng,
                 nlohmann::ordered_json& record, const std::string& file, int line) {
  Drawn d;
  for (const auto& decl : decls) {
    ParamSpec spec;
    int where_line = line;
    if (const auto it = given.find(decl.name); it != given.end()) {
      spec = it->second;
      where_line = spec.line;
    } else {
      if (!decl.fallback) throw InputError(file, line, std::string("missing parameter '") + decl.name + "' (" + decl.meaning + ")");
      spec.components.push_back({parseAmount(decl.fallback, decl.kind, decl.name, "default"), {}, false, false});
      spec.components[0].hi = spec.components[0].lo;
    }
    const bool per_axis = spec.components.size() == 3;
    const int axes = decl.kind == ParamKind::Length3 ? 3 : 1;
    Vec3 v;
    double shared_u = rng.uniform();  // isotropic: one draw for all axes
    double out[3] = {0, 0, 0};
    for (int ax = 0; ax < axes; ++ax) {
      const ParamRange& r = spec.components[per_axis ? ax : 0];
      const double u = per_axis && ax > 0 ? rng.uniform() : shared_u;
      const int res_axis = decl.kind == ParamKind::Length3 ? ax : -1;
      const double lo = resolveAmount(r.lo, scale, res_axis), hi = resolveAmount(r.hi, scale, res_axis);
      if (r.range && lo > hi)
        throw InputError(file, where_line, std::string("the range of ") + decl.name + " resolves to min " + show(lo) + " > max " + show(hi));
      double x = drawComponent(r, u, scale, res_axis);
      if (decl.kind == ParamKind::Count) x = r.range ? std::min(std::floor(lo + u * (std::floor(hi) - lo + 1)), std::floor(hi)) : std::round(x);
      checkRange(x, decl.lo, false, decl.hi, false, Where{file, where_line}, decl.name);
      checkGridBounds(decl, x, scale.grid, res_axis, Where{file, where_line});
      out[ax] = x;
    }
    v = Vec3(out[0], axes == 3 ? out[1] : out[0], axes == 3 ? out[2] : out[0]);
    d.values[decl.name] = v;
    if (axes == 3)
      record[decl.name] = {v.x, v.y, v.z};
    else if (decl.kind == ParamKind::Count)
      record[decl.name] = static_cast<std::int64_t>(v.x);
    else
      record[decl.name] = v.x;
  }
  return d;
}

}  // namespace angiosynth
