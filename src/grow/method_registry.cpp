// The growth methods by name, and their reference generated from their declarations so that
// `angiosynth methods` and the docs cannot drift from the readers.
#include <sstream>
#include <stdexcept>

#include "grow/cco/setup.hpp"
#include "grow/colonisation/setup.hpp"
#include "grow/dcco/setup.hpp"
#include "grow/lsystem/setup.hpp"
#include "grow/method.hpp"
#include "grow/vascusynth/setup.hpp"

namespace angiosynth {

// Methods that grow whole: callers ask parts() first.
PartTaskSummary PreparedGrowth::growPart(std::uint64_t, std::uint64_t, int, const std::filesystem::path&) const {
  throw std::logic_error("growPart on a method that grows whole");
}
Forest PreparedGrowth::joinParts(std::uint64_t, std::uint64_t, const std::filesystem::path&, GrowthReport&, const ProgressFn&) const {
  throw std::logic_error("joinParts on a method that grows whole");
}

const std::vector<const GrowthMethod*>& growthMethods() {
  static const std::vector<const GrowthMethod*> all{&kVascuSynthMethod, &kCcoMethod, &kDccoMethod, &kColonisationMethod, &kLsystemMethod};
  return all;
}

const GrowthMethod* findGrowthMethod(const std::string& name) {
  for (const auto* m : growthMethods())
    if (name == m->name) return m;
  return nullptr;
}

std::string growthMethodNames() {
  std::string out;
  for (const auto* m : growthMethods()) out += (out.empty() ? "" : ", ") + std::string(m->name);
  return out;
}

const GrowthMethod* methodDeclaring(const std::string& table, const std::string& key, const GrowthMethod* self) {
  for (const auto* m : growthMethods()) {
    if (m == self) continue;
    for (const auto& p : m->params)
      if (table == p.table && key == p.key) return m;
  }
  return nullptr;
}

std::string methodReference() {
  std::ostringstream o;
  for (const auto* m : growthMethods()) {
    o << "- **`" << m->name << "`**: " << m->summary << ".\n";
    for (const auto& p : m->params) {
      o << "  - `[" << p.table << "] " << p.key << "`";
      if (*p.unit) o << " (" << p.unit << ")";
      o << ": " << p.meaning;
      if (p.fallback)
        o << "; default `" << p.fallback << "`";
      else
        o << "; required";
      o << ".\n";
    }
  }
  return o.str();
}

}  // namespace angiosynth
