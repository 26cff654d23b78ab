#include "io/growth_domain_files.hpp"

#include <nifti/nifti1_io.h>

#include <cmath>
#include <memory>

#include "core/error.hpp"
#include "core/memory.hpp"
#include "io/map_files.hpp"
#include "io/param_checks.hpp"

namespace angiosynth {
namespace {

// Bytes per voxel a mask domain needs: value, depth, supply index, sampler (two doubles).
constexpr std::uint64_t kMaskBytesPerVoxel = 4 + 4 + 2 + 16 + 4;

}  // namespace

void checkDomainMemory(std::int64_t voxels, std::uint64_t limit, const std::string& file, int line, const std::string& what) {
  const std::uint64_t need = std::uint64_t(voxels) * kMaskBytesPerVoxel;
  if (need > limit)
    throw InputError(file, line, what + " of " + std::to_string(voxels) + " voxels needs " + formatBytes(need) +
                                     " to grow in, more than the limit of " + formatBytes(limit) +
                                     "; use a coarser voxel_size or raise --memory-limit");
}

bool isNifti(const std::filesystem::path& p) {
  const auto s = p.string();
  return s.ends_with(".nii") || s.ends_with(".nii.gz");
}

DemandMap readNiftiMask(const std::filesystem::path& file, std::uint64_t limit) {
  const std::string f = file.string();
  if (!std::filesystem::is_regular_file(file)) throw InputError(f, 0, "the mask is not a regular file (missing, a directory or a device)");
  std::unique_ptr<nifti_image, decltype(&nifti_image_free)> head(nifti_image_read(f.c_str(), 0), &nifti_image_free);
  if (!head) throw InputError(f, 0, "cannot read this file as a NIfTI image");
  if (head->nx > Limits::kMaxVoxelsPerAxis || head->ny > Limits::kMaxVoxelsPerAxis || head->nz > Limits::kMaxVoxelsPerAxis)
    throw InputError(f, 0, "a mask of " + std::to_string(head->nx) + " x " + std::to_string(head->ny) + " x " +
                               std::to_string(head->nz) + " voxels; allowed: at most 100000 per axis");
  // All seven dimensions count: the library reads nvox = nx·…·nw values, whatever dim[0] says.
  if (head->nx < 1 || head->ny < 1 || head->nz < 1 || head->nt > 1 || head->nu > 1 || head->nv > 1 || head->nw > 1 ||
      head->nvox != std::size_t(head->nx) * std::size_t(head->ny) * std::size_t(head->nz))
    throw InputError(f, 0, "a mask must be one 3D (or one-slice 2D) volume; this one has dims " + std::to_string(head->nx) +
                               " " + std::to_string(head->ny) + " " + std::to_string(head->nz) + " " + std::to_string(head->nt) +
                               " " + std::to_string(head->nu) + " " + std::to_string(head->nv) + " " + std::to_string(head->nw));
  const double dx = std::abs(head->dx), dy = std::abs(head->dy), dz = std::abs(head->dz);
  if (!(dx > 0) || std::abs(dy - dx) > 1e-6 * dx || (head->nz > 1 && std::abs(dz - dx) > 1e-6 * dx))
    throw InputError(f, 0, "mask voxels must be isotropic (got " + show(dx) + " x " + show(dy) + " x " + show(dz) +
                               "); resample the mask");
  // Lengths in mm whatever the header's unit.
  const int unit = XYZT_TO_SPACE(head->xyz_units);
  const double voxel_mm = dx * (unit == NIFTI_UNITS_METER ? 1e3 : unit == NIFTI_UNITS_MICRON ? 1e-3 : 1.0);
  if (!(voxel_mm >= Limits::kMinVoxel && voxel_mm <= Limits::kMaxVoxel))
    throw InputError(f, 0, "voxel size " + show(voxel_mm) + " mm (pixdim) is out of range; allowed: 1e-4 to 1e4 mm");
  // The voxel type too, before the voxels are read (the memory check assumes at most 8 bytes each).
  switch (head->datatype) {
    case DT_UINT8: case DT_INT8: case DT_INT16: case DT_UINT16: case DT_INT32: case DT_UINT32: case DT_FLOAT32: case DT_FLOAT64: break;
    default: throw InputError(f, 0, std::string("unsupported NIfTI data type ") + nifti_datatype_string(head->datatype) +
                                        "; allowed: 8/16/32-bit integers, float32, float64");
  }
  DemandMap m;
  m.dims = {static_cast<std::int32_t>(head->nx), static_cast<std::int32_t>(head->ny), static_cast<std::int32_t>(head->nz)};
  checkDomainMemory(m.voxelCount(), limit, f, 0, "the mask");
  std::unique_ptr<nifti_image, decltype(&nifti_image_free)> img(nifti_image_read(f.c_str(), 1), &nifti_image_free);
  if (!img || !img->data) throw InputError(f, 0, "cannot read the voxels of this NIfTI image");
  m.voxel_mm = voxel_mm;
  m.demand.resize(m.voxelCount());
  const auto n = static_cast<std::size_t>(m.voxelCount());
  const auto convert = [&](auto* p) {
    for (std::size_t i = 0; i < n; ++i) m.demand[i] = static_cast<float>(p[i]);
  };
  switch (img->datatype) {
    case DT_UINT8: convert(static_cast<const std::uint8_t*>(img->data)); break;
    case DT_INT8: convert(static_cast<const std::int8_t*>(img->data)); break;
    case DT_INT16: convert(static_cast<const std::int16_t*>(img->data)); break;
    case DT_UINT16: convert(static_cast<const std::uint16_t*>(img->data)); break;
    case DT_INT32: convert(static_cast<const std::int32_t*>(img->data)); break;
    case DT_UINT32: convert(static_cast<const std::uint32_t*>(img->data)); break;
    case DT_FLOAT32: convert(static_cast<const float*>(img->data)); break;
    case DT_FLOAT64: convert(static_cast<const double*>(img->data)); break;
    default: throw InputError(f, 0, std::string("unsupported NIfTI data type ") + nifti_datatype_string(img->datatype) +
                                        "; allowed: 8/16/32-bit integers, float32, float64");
  }
  if (img->scl_slope != 0 && (img->scl_slope != 1 || img->scl_inter != 0))
    for (auto& v : m.demand) v = static_cast<float>(v * img->scl_slope + img->scl_inter);
  for (auto& v : m.demand)
    if (!(v > 0)) v = 0;  // negative and NaN values are outside
  m.supply_index.assign(m.demand.size(), 0);
  m.supply_sets = {{}};
  return m;
}

}  // namespace angiosynth
