// NIfTI masks for CCO domains: header and voxels.
#include "fuzz_support.hpp"
#include "io/growth_domain_files.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace angiosynth;
  const auto file = fuzz::writeInput(data, size, "mask.nii");
  return fuzz::expectOnlyInputErrors([&] { readNiftiMask(file, fuzz::kMemoryLimit); });
}
