#include "io/deflate_stream.hpp"

#include <zlib.h>

#include <algorithm>
#include <vector>

#include "core/error.hpp"

namespace angiosynth {

void deflateInto(std::ostream& out, const void* data, std::size_t bytes, DeflateFraming framing, const std::filesystem::path& file) {
  z_stream zs{};
  const int window_bits = framing == DeflateFraming::Gzip ? 15 + 16 : 15;
  if (deflateInit2(&zs, 6, Z_DEFLATED, window_bits, 8, Z_DEFAULT_STRATEGY) != Z_OK) throw InputError(file.string(), 0, "cannot start compression");
  const auto* in = static_cast<const unsigned char*>(data);
  std::size_t left = bytes;
  std::vector<unsigned char> buf(1 << 20);
  int flush = Z_NO_FLUSH;
  do {
    // zlib counts input in 32-bit units: larger volumes go in 1 GiB pieces.
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
}

}  // namespace angiosynth
