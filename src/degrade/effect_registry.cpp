#include "degrade/effect.hpp"

namespace angiosynth {

extern const EffectType kGaussianNoise, kUniformNoise, kImpulseNoise, kRicianNoise, kPoissonNoise, kBlur, kDropout, kShadow, kBiasField, kContrast,
    kTexture, kAttenuation, kWarp, kGibbs, kKSpaceSpike, kMotionGhost, kUndersample, kCompartments, kVoronoi, kDecoys, kBone, kCalcification, kInflow,
    kSlab, kProjection, kSpeckle, kPartialFourier;

const std::vector<const EffectType*>& effectTypes() {
  static const std::vector<const EffectType*> all{
      &kGaussianNoise, &kUniformNoise, &kImpulseNoise, &kRicianNoise, &kPoissonNoise,  &kBlur,        &kDropout,     &kShadow,      &kBiasField,
      &kContrast,      &kTexture,      &kAttenuation,  &kWarp,        &kGibbs,         &kKSpaceSpike, &kMotionGhost, &kUndersample, &kPartialFourier,
      &kCompartments,  &kVoronoi,      &kDecoys,       &kBone,        &kCalcification, &kInflow,      &kSlab,        &kProjection,  &kSpeckle};
  return all;
}

const EffectType* findEffectType(const std::string& name) {
  for (const auto* t : effectTypes())
    if (name == t->name) return t;
  return nullptr;
}

}  // namespace angiosynth
