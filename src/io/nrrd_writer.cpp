// NRRD 4 with gzip encoding. NRRD's usual space is LPS, so RAS axes x and y are negated.
#include <cstdio>
#include <fstream>
#include <sstream>

#include "core/error.hpp"
#include "core/format.hpp"
#include "io/deflate_stream.hpp"
#include "io/volume_writers.hpp"

namespace angiosynth {

void writeNrrd(const std::filesystem::path& file, const VolumeView& v) {
  const VolumeGrid& g = *v.grid;
  static const char* kTypes[] = {"uint8", "int16", "uint16", "uint32", "float"};
  std::ostringstream h;
  h << "NRRD0004\n# " << v.description << "\n"
    << "type: " << kTypes[static_cast<int>(v.type)] << "\ndimension: 3\nspace: left-posterior-superior\n"
    << "sizes: " << g.dims[0] << " " << g.dims[1] << " " << g.dims[2] << "\n"
    << "space directions: (" << exactNumber(-g.spacing_mm.x) << ",0,0) (0," << exactNumber(-g.spacing_mm.y) << ",0) (0,0,"
    << exactNumber(g.spacing_mm.z) << ")\n"
    << "kinds: domain domain domain\nendian: little\nencoding: gzip\n"
    << "space origin: (" << exactNumber(-g.origin_mm.x) << "," << exactNumber(-g.origin_mm.y) << "," << exactNumber(g.origin_mm.z) << ")\n";
  if (v.label) h << "# label map\n";
  h << "\n";
  std::ofstream out(file, std::ios::binary);
  out << h.str();
  deflateInto(out, v.data, static_cast<std::size_t>(g.voxelCount()) * voxelBytes(v.type), DeflateFraming::Gzip, file);
  out.flush();
  if (!out) throw InputError(file.string(), 0, "writing failed (disk full?)");
}

}  // namespace angiosynth
