// The reference of every effect and its parameters, generated from the declarations so that
// `angiosynth effects` and the docs cannot drift from the code.
#include <algorithm>
#include <sstream>

#include "degrade/effect.hpp"

namespace angiosynth {
namespace {

const char* kindName(ParamKind k) {
  switch (k) {
    case ParamKind::Intensity: return "intensity";
    case ParamKind::Length: return "length";
    case ParamKind::Length3: return "length, or 3 per axis";
    case ParamKind::Probability: return "probability";
    case ParamKind::Count: return "whole number";
    case ParamKind::Number: return "number";
  }
  return "";
}

// A value of the parameter's kind within its bounds, for a parameter the effect needs given.
std::string exampleValue(const ParamDecl& p) {
  const auto number = [&](double v) {
    std::ostringstream o;
    o << std::clamp(v, p.lo, p.hi);
    return o.str();
  };
  switch (p.kind) {
    case ParamKind::Intensity: return "\"0.1 contrast\"";
    case ParamKind::Length:
    case ParamKind::Length3: return "\"2 voxel\"";
    case ParamKind::Probability: return number(0.01);
    case ParamKind::Count: return number(2);
    case ParamKind::Number: return number(1);
  }
  return "";
}

}  // namespace

std::string exampleEffectToml(const EffectType& t) {
  std::string o = "[[effect]]\ntype = \"" + std::string(t.name) + "\"\n";
  for (const auto& p : t.params)
    if (!p.fallback) o += std::string(p.name) + " = " + exampleValue(p) + "\n";
  return o;
}

std::string effectReference() {
  std::ostringstream o;
  for (const auto* t : effectTypes()) {
    o << "- **`" << t->name << "`**: " << t->summary << ".\n";
    for (const auto& p : t->params) {
      o << "  - `" << p.name << "` (" << kindName(p.kind) << "): " << p.meaning;
      if (p.fallback)
        o << "; default `" << p.fallback << "`";
      else
        o << "; required";
      o << ".\n";
    }
  }
  o << "- Every effect also takes `probability` (default 1): the chance that it is applied at all.\n";
  return o.str();
}

}  // namespace angiosynth
