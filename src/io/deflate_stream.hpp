#pragma once
#include <cstddef>
#include <filesystem>
#include <ostream>

namespace angiosynth {

enum class DeflateFraming { Gzip, Zlib };

// Deflates `bytes` bytes at `data` (level 6) into `out`, in gzip framing (NRRD's gzip encoding)
// or zlib's own (MetaImage's CompressedData); `file` names the output in errors.
void deflateInto(std::ostream& out, const void* data, std::size_t bytes, DeflateFraming framing, const std::filesystem::path& file);

}  // namespace angiosynth
