// NRRD 4 with gzip encoding. NRRD's usual space is LPS, so RAS axes x and y are negated.
#include <zlib.h>

#include <cstdio>
#include <fstream>
#include <sstream>

#include "core/error.hpp"
#include "core/format.hpp"
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
    << "space origin: (" << exactNumber(-g.origin_mm.x) << "," << exactNumber(-g.origin_mm.y) << ","
    << exactNumber(g.origin_mm.z) << ")\n";
  if (v.label) h << "# label map\n";
  h << "\n";
  std::ofstream out(file, std::ios::binary);
  out << h.str();
  z_stream zs{};
  if (deflateInit2(&zs, 6, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY) != Z_OK)
    throw InputError(file.string(), 0, "cannot start gzip compression");
  const auto* in = static_cast<const unsigned char*>(v.data);
  std::size_t left = static_cast<std::size_t>(g.voxelCount()) * voxelBytes(v.type);
  std::vector<unsigned char> buf(1 << 20);
  int flush = Z_NO_FLUSH;
  do {
    const std::size_t chunk = std::min<std::size_t>(left, 1u << 30);
    zs.next_in = const_cast<unsigned char*>(in);
    zs.avail_in = static_cast<uInt>(chunk);
    in += chunk;
    left -= chunk;
    flush = left == 0 ? Z_FINISH : Z_NO_FLUSH;
    do {
      zs.next_out = buf.data();
      zs.avail_out = static_cast<uInt>(buf.size());
      deflate(&zs, flush);
      out.write(reinterpret_cast<const char*>(buf.data()), static_cast<std::streamsize>(buf.size() - zs.avail_out));
    } while (zs.avail_out == 0);
  } while (flush != Z_FINISH);
  deflateEnd(&zs);
  out.flush();
  if (!out) throw InputError(file.string(), 0, "writing failed (disk full?)");
}

}  // namespace angiosynth
