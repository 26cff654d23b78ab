#include "io/nifti_reader.hpp"

#include <nifti/nifti1_io.h>

#include <cmath>
#include <cstring>
#include <memory>
#include <vector>

#include "core/error.hpp"
#include "core/memory.hpp"
#include "settings/param_checks.hpp"

namespace angiosynth {

NiftiVolume readNiftiVolume(const std::filesystem::path& file, std::uint64_t limit, std::uint64_t bytes_per_voxel, const char* what) {
  const std::string f = file.string();
  if (!std::filesystem::is_regular_file(file))
    throw InputError(f, 0, std::string(what) + " is not a regular file (missing, a directory or a device)");
  std::unique_ptr<nifti_image, decltype(&nifti_image_free)> head(nifti_image_read(f.c_str(), 0), &nifti_image_free);
  if (!head) throw InputError(f, 0, "cannot read this file as a NIfTI image");
  if (head->nx > Limits::kMaxVoxelsPerAxis || head->ny > Limits::kMaxVoxelsPerAxis || head->nz > Limits::kMaxVoxelsPerAxis)
    throw InputError(f, 0,
                     std::string(what) + " of " + std::to_string(head->nx) + " x " + std::to_string(head->ny) + " x " + std::to_string(head->nz) +
                         " voxels; allowed: at most 100000 per axis");
  // All seven dimensions count: the library reads nvox = nx·…·nw values, whatever dim[0] says.
  if (head->nx < 1 || head->ny < 1 || head->nz < 1 || head->nt > 1 || head->nu > 1 || head->nv > 1 || head->nw > 1 ||
      head->nvox != std::size_t(head->nx) * std::size_t(head->ny) * std::size_t(head->nz))
    throw InputError(f, 0,
                     std::string(what) + " must be one 3D (or one-slice 2D) volume; this one has dims " + std::to_string(head->nx) + " " +
                         std::to_string(head->ny) + " " + std::to_string(head->nz) + " " + std::to_string(head->nt) + " " + std::to_string(head->nu) +
                         " " + std::to_string(head->nv) + " " + std::to_string(head->nw));
  const int unit = XYZT_TO_SPACE(head->xyz_units);
  const double to_mm = unit == NIFTI_UNITS_METER ? 1e3 : unit == NIFTI_UNITS_MICRON ? 1e-3 : 1.0;
  const double d[3] = {std::abs(head->dx) * to_mm, std::abs(head->dy) * to_mm, std::abs(head->dz) * to_mm};
  for (double v : d)
    if (!(v >= Limits::kMinVoxel && v <= Limits::kMaxVoxel))
      throw InputError(f, 0, "voxel size " + show(v) + " mm (pixdim) is out of range; allowed: 1e-4 to 1e4 mm");
  // The voxel type too, before the voxels are read (the memory check assumes at most 8 bytes each).
  switch (head->datatype) {
    case DT_UINT8:
    case DT_INT8:
    case DT_INT16:
    case DT_UINT16:
    case DT_INT32:
    case DT_UINT32:
    case DT_FLOAT32:
    case DT_FLOAT64: break;
    default:
      throw InputError(
          f, 0,
          std::string("unsupported NIfTI data type ") + nifti_datatype_string(head->datatype) + "; allowed: 8/16/32-bit integers, float32, float64");
  }
  VolumeGrid g;
  g.dims = {static_cast<std::int32_t>(head->nx), static_cast<std::int32_t>(head->ny), static_cast<std::int32_t>(head->nz)};
  g.spacing_mm = Vec3(d[0], d[1], d[2]);
  const std::uint64_t need = std::uint64_t(g.voxelCount()) * (bytes_per_voxel + 8);
  if (need > limit)
    throw InputError(f, 0,
                     std::string(what) + " of " + std::to_string(g.voxelCount()) + " voxels needs " + formatBytes(need) +
                         ", more than the limit of " + formatBytes(limit) + "; raise --memory-limit");
  // The voxels read here, not by nifti_image_read: on a file that ends early it fills the missing
  // voxels with 0 and carries on, which would score a truncated prediction as if it were whole.
  nifti_image* opened = nullptr;
  znzFile fp = nifti_image_open(f.c_str(), const_cast<char*>("rb"), &opened);
  std::unique_ptr<nifti_image, decltype(&nifti_image_free)> img(opened, &nifti_image_free);
  if (znz_isnull(fp) || !img) throw InputError(f, 0, "cannot read the voxels of this NIfTI image");
  if (img->iname_offset < 0 || znzseek(fp, long(img->iname_offset), SEEK_SET) < 0) {
    znzclose(fp);
    throw InputError(f, 0, "the voxel data's offset " + std::to_string(img->iname_offset) + " lies beyond the file (a truncated file)");
  }
  const std::size_t bytes = nifti_get_volsize(img.get());
  std::vector<unsigned char> raw(bytes);
  const std::size_t got = znzread(raw.data(), 1, bytes, fp);
  znzclose(fp);
  if (got != bytes)
    throw InputError(f, 0,
                     "the voxel data ends after " + std::to_string(got == std::size_t(-1) ? 0 : got) + " of its " + std::to_string(bytes) +
                         " bytes (a truncated file); allowed: a complete NIfTI image");
  if (img->swapsize > 1 && img->byteorder != nifti_short_order()) nifti_swap_Nbytes(bytes / std::size_t(img->swapsize), img->swapsize, raw.data());
  const mat44& m = img->sform_code > 0 ? img->sto_xyz : img->qto_xyz;
  NiftiVolume out;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) out.affine[std::size_t(r * 4 + c)] = double(m.m[r][c]) * to_mm;
  if (img->sform_code > 0 && img->qform_code > 0) {
    std::array<double, 12> q{};
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) q[std::size_t(r * 4 + c)] = double(img->qto_xyz.m[r][c]) * to_mm;
    out.other_affine = q;
  }
  g.origin_mm = Vec3(out.affine[3], out.affine[7], out.affine[11]);
  out.values = Volume<float>(g);
  const auto n = static_cast<std::size_t>(g.voxelCount());
  auto& v = out.values.data;
  const auto convert = [&](auto type) {
    using T = decltype(type);
    for (std::size_t i = 0; i < n; ++i) {
      T x;
      std::memcpy(&x, raw.data() + i * sizeof(T), sizeof(T));
      v[i] = static_cast<float>(x);
    }
  };
  switch (img->datatype) {
    case DT_UINT8: convert(std::uint8_t()); break;
    case DT_INT8: convert(std::int8_t()); break;
    case DT_INT16: convert(std::int16_t()); break;
    case DT_UINT16: convert(std::uint16_t()); break;
    case DT_INT32: convert(std::int32_t()); break;
    case DT_UINT32: convert(std::uint32_t()); break;
    case DT_FLOAT32: convert(float()); break;
    case DT_FLOAT64: convert(double()); break;
    default: throw InputError(f, 0, "unsupported NIfTI data type");
  }
  if (img->scl_slope != 0 && (img->scl_slope != 1 || img->scl_inter != 0))
    for (auto& x : v) x = static_cast<float>(x * img->scl_slope + img->scl_inter);
  return out;
}

}  // namespace angiosynth
