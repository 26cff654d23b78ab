// NIfTI-1 through niftilib's header helpers, written with zlib so that every write is checked.
#include <nifti/nifti1_io.h>
#include <zlib.h>

#include <unistd.h>

#include <cstring>
#include <memory>

#include "core/error.hpp"
#include "files/atomic_file.hpp"
#include "io/volume_writers.hpp"

namespace angiosynth {

std::size_t voxelBytes(VoxelType t) {
  switch (t) {
    case VoxelType::UInt8: return 1;
    case VoxelType::Int16:
    case VoxelType::UInt16: return 2;
    case VoxelType::UInt32:
    case VoxelType::Float32: return 4;
  }
  return 1;
}

namespace {

int niftiType(VoxelType t) {
  switch (t) {
    case VoxelType::UInt8: return DT_UINT8;
    case VoxelType::Int16: return DT_INT16;
    case VoxelType::UInt16: return DT_UINT16;
    case VoxelType::UInt32: return DT_UINT32;
    case VoxelType::Float32: return DT_FLOAT32;
  }
  return DT_FLOAT32;
}

}  // namespace

namespace {

// The header and voxels into `out` (closed here); the grid's axis-aligned geometry, or `affine`
// (rows of the voxel-to-world matrix) when given.
void writeNiftiStream(gzFile out, const std::filesystem::path& file, const VolumeView& v, const std::array<double, 12>* affine) {
  const VolumeGrid& g = *v.grid;
  const int dims[8] = {3, g.dims[0], g.dims[1], g.dims[2], 1, 1, 1, 1};
  std::unique_ptr<nifti_1_header, decltype(&std::free)> h(nifti_make_new_header(dims, niftiType(v.type)), &std::free);
  if (!h) {
    gzclose(out);
    throw InputError(file.string(), 0, "cannot build a NIfTI header");
  }
  h->pixdim[0] = 1;  // qfac: right-handed
  h->pixdim[1] = static_cast<float>(g.spacing_mm.x);
  h->pixdim[2] = static_cast<float>(g.spacing_mm.y);
  h->pixdim[3] = static_cast<float>(g.spacing_mm.z);
  h->xyzt_units = NIFTI_UNITS_MM;
  h->qform_code = NIFTI_XFORM_SCANNER_ANAT;
  h->sform_code = NIFTI_XFORM_SCANNER_ANAT;
  if (affine) {
    const auto& m = *affine;
    for (int c = 0; c < 4; ++c) h->srow_x[c] = float(m[c]), h->srow_y[c] = float(m[4 + c]), h->srow_z[c] = float(m[8 + c]);
    mat44 r;
    for (int row = 0; row < 3; ++row)
      for (int c = 0; c < 4; ++c) r.m[row][c] = float(m[4 * row + c]);
    r.m[3][0] = r.m[3][1] = r.m[3][2] = 0, r.m[3][3] = 1;
    float qb, qc, qd, qx, qy, qz, dx, dy, dz, qfac;
    nifti_mat44_to_quatern(r, &qb, &qc, &qd, &qx, &qy, &qz, &dx, &dy, &dz, &qfac);
    h->quatern_b = qb, h->quatern_c = qc, h->quatern_d = qd;
    h->qoffset_x = qx, h->qoffset_y = qy, h->qoffset_z = qz;
    h->pixdim[0] = qfac, h->pixdim[1] = dx, h->pixdim[2] = dy, h->pixdim[3] = dz;
  } else {
    h->quatern_b = h->quatern_c = h->quatern_d = 0;  // identity rotation
    h->qoffset_x = static_cast<float>(g.origin_mm.x);
    h->qoffset_y = static_cast<float>(g.origin_mm.y);
    h->qoffset_z = static_cast<float>(g.origin_mm.z);
    const float srow[3][4] = {{float(g.spacing_mm.x), 0, 0, float(g.origin_mm.x)},
                              {0, float(g.spacing_mm.y), 0, float(g.origin_mm.y)},
                              {0, 0, float(g.spacing_mm.z), float(g.origin_mm.z)}};
    std::memcpy(h->srow_x, srow[0], sizeof srow[0]);
    std::memcpy(h->srow_y, srow[1], sizeof srow[1]);
    std::memcpy(h->srow_z, srow[2], sizeof srow[2]);
  }
  h->scl_slope = 1;
  h->scl_inter = 0;
  if (v.label) {
    h->intent_code = NIFTI_INTENT_LABEL;
    std::strncpy(h->intent_name, "label", sizeof h->intent_name - 1);
  }
  std::strncpy(h->descrip, v.description.c_str(), sizeof h->descrip - 1);
  h->vox_offset = 352;
  std::memcpy(h->magic, "n+1\0", 4);

  gzbuffer(out, 1 << 20);
  const char extender[4] = {0, 0, 0, 0};
  bool ok = gzwrite(out, h.get(), sizeof(nifti_1_header)) == int(sizeof(nifti_1_header)) && gzwrite(out, extender, 4) == 4;
  const auto* bytes = static_cast<const unsigned char*>(v.data);
  std::size_t left = static_cast<std::size_t>(g.voxelCount()) * voxelBytes(v.type);
  while (ok && left > 0) {
    const unsigned chunk = static_cast<unsigned>(std::min<std::size_t>(left, 1u << 30));
    ok = gzwrite(out, bytes, chunk) == int(chunk);
    bytes += chunk;
    left -= chunk;
  }
  if (gzclose(out) != Z_OK || !ok) throw InputError(file.string(), 0, "writing failed (disk full?)");
}

}  // namespace

void writeNifti(const std::filesystem::path& file, const VolumeView& v) {
  gzFile out = gzopen(file.c_str(), "wb6");
  if (!out) throw InputError(file.string(), 0, "cannot open for writing");
  writeNiftiStream(out, file, v, nullptr);
}

void writeNiftiAtomically(const std::filesystem::path& file, const VolumeView& v, const std::array<double, 12>* affine, bool replace) {
  AtomicFile f(file);
  std::fflush(f.stream());
  gzFile out = gzdopen(::dup(::fileno(f.stream())), "wb6");
  if (!out) throw InputError(file.string(), 0, "cannot open for writing");
  writeNiftiStream(out, file, v, affine);
  f.commit(replace);
}

}  // namespace angiosynth
