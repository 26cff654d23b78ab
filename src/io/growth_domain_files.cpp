#include "io/growth_domain_files.hpp"

#include <cmath>
#include <memory>

#include "core/error.hpp"
#include "core/memory.hpp"
#include "io/map_files.hpp"
#include "io/nifti_reader.hpp"
#include "settings/param_checks.hpp"

namespace angiosynth {
namespace {

// Bytes per voxel a mask domain needs: value, depth, supply index, sampler (two doubles).
constexpr std::uint64_t kMaskBytesPerVoxel = 4 + 4 + 2 + 16 + 4;

}  // namespace

void checkDomainMemory(std::int64_t voxels, std::uint64_t limit, const std::string& file, int line, const std::string& what) {
  const std::uint64_t need = std::uint64_t(voxels) * kMaskBytesPerVoxel;
  if (need > limit)
    throw InputError(file, line,
                     what + " of " + std::to_string(voxels) + " voxels needs " + formatBytes(need) + " to grow in, more than the limit of " +
                         formatBytes(limit) + "; use a coarser voxel_size or raise --memory-limit");
}

bool isNifti(const std::filesystem::path& p) {
  const auto s = p.string();
  return s.ends_with(".nii") || s.ends_with(".nii.gz");
}

DemandMap readNiftiMask(const std::filesystem::path& file, std::uint64_t limit) {
  const std::string f = file.string();
  NiftiVolume nv = readNiftiVolume(file, limit, kMaskBytesPerVoxel, "a mask");
  const Vec3 d = nv.values.grid.spacing_mm;
  const bool flat = nv.values.grid.dims[2] == 1;
  if (std::abs(d.y - d.x) > 1e-6 * d.x || (!flat && std::abs(d.z - d.x) > 1e-6 * d.x))
    throw InputError(f, 0, "mask voxels must be isotropic (got " + show(d.x) + " x " + show(d.y) + " x " + show(d.z) + "); resample the mask");
  DemandMap m;
  m.dims = nv.values.grid.dims;
  checkDomainMemory(m.voxelCount(), limit, f, 0, "the mask");
  m.voxel_mm = d.x;
  m.demand.assign(nv.values.data.begin(), nv.values.data.end());
  for (auto& v : m.demand)
    if (!(v > 0)) v = 0;  // negative and NaN values are outside
  m.supply_index.assign(m.demand.size(), 0);
  m.supply_sets = {{}};
  return m;
}

}  // namespace angiosynth
