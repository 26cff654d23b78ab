// The reference of every effect and its parameters, generated from the declarations so that
// `angiosynth effects` and the docs cannot drift from the code.
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

}  // namespace

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
