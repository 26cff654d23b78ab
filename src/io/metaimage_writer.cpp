// MetaImage (.mha: ITK's MetaIO header and the voxels in one file, zlib-compressed), read by ITK,
// 3D Slicer, ParaView and elastix. MetaIO's physical space is LPS, as ITK's: RAS axes x and y are
// negated in the direction matrix and the offset, the same geometry the NIfTI files describe.
#include <fstream>
#include <sstream>

#include "core/error.hpp"
#include "core/format.hpp"
#include "io/deflate_stream.hpp"
#include "io/volume_writers.hpp"

namespace angiosynth {

void writeMetaImage(const std::filesystem::path& file, const VolumeView& v) {
  const VolumeGrid& g = *v.grid;
  static const char* kTypes[] = {"MET_UCHAR", "MET_SHORT", "MET_USHORT", "MET_UINT", "MET_FLOAT"};
  // CompressedDataSize precedes the voxels: compressed in memory first.
  std::ostringstream packed;
  deflateInto(packed, v.data, static_cast<std::size_t>(g.voxelCount()) * voxelBytes(v.type), DeflateFraming::Zlib, file);
  const std::string voxels = std::move(packed).str();
  std::ofstream out(file, std::ios::binary);
  out << "ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = False\n"
      << "CompressedData = True\nCompressedDataSize = " << voxels.size() << "\n"
      << "TransformMatrix = -1 0 0 0 -1 0 0 0 1\n"
      << "Offset = " << exactNumber(-g.origin_mm.x) << " " << exactNumber(-g.origin_mm.y) << " " << exactNumber(g.origin_mm.z) << "\n"
      << "CenterOfRotation = 0 0 0\nAnatomicalOrientation = LPI\n"
      << "ElementSpacing = " << exactNumber(g.spacing_mm.x) << " " << exactNumber(g.spacing_mm.y) << " " << exactNumber(g.spacing_mm.z) << "\n"
      << "DimSize = " << g.dims[0] << " " << g.dims[1] << " " << g.dims[2] << "\n"
      << "ElementType = " << kTypes[static_cast<int>(v.type)] << "\nElementDataFile = LOCAL\n";
  out.write(voxels.data(), static_cast<std::streamsize>(voxels.size()));
  out.flush();
  if (!out) throw InputError(file.string(), 0, "writing failed (disk full?)");
}

}  // namespace angiosynth
