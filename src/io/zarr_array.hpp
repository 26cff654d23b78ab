#pragma once
// Arrays of a Zarr store (format version 2, the one OME-NGFF 0.4 builds on): a directory with a
// .zarray description and one compressed file per chunk, keyed "z/y/x". A chunk whose voxels all
// equal the fill value is not stored (readers return the fill value for it), so a sparse vessel
// tree costs disk only where it is. Chunks are written whole or not at all, so a writer killed
// mid-chunk leaves the chunk as it was.
#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

#include "io/volume_writers.hpp"

namespace angiosynth {

enum class ZarrCodec {
  Blosc,  // Blosc 1 with LZ4 and byte shuffle: zarr-python's default, fast on mostly empty chunks
  Zlib,   // zlib (deflate in zlib framing): readable where Blosc is not built
};
// "blosc" or "zlib"; null when unknown.
const ZarrCodec* findZarrCodec(std::string_view name);
std::string_view zarrCodecName(ZarrCodec c);

struct ZarrArray {
  std::filesystem::path dir;
  std::array<std::int64_t, 3> shape{0, 0, 0};   // z, y, x (x varies fastest in memory)
  std::array<std::int64_t, 3> chunks{0, 0, 0};  // z, y, x
  VoxelType type = VoxelType::Float32;
  double fill = 0;  // the value of voxels in chunks that are not stored
  ZarrCodec codec = ZarrCodec::Blosc;
  int level = 5;  // Blosc clevel 0–9, zlib level 0–9

  // The .zarray text (JSON); the same bytes for the same array.
  std::string metadata() const;
  std::size_t chunkBytes() const { return std::size_t(chunks[0] * chunks[1] * chunks[2]) * voxelBytes(type); }
  // Chunks per axis (z, y, x).
  std::array<std::int64_t, 3> chunkGrid() const;
  std::filesystem::path chunkPath(const std::array<std::int64_t, 3>& chunk) const;
  // Writes .zarray (atomically, replacing an earlier one).
  void writeMetadata() const;
  // Compresses a whole chunk (chunkBytes() bytes, C order; voxels beyond the array's edge are
  // stored too, as Zarr asks) and writes it, unless every voxel equals the fill value. Returns
  // the bytes stored (0: nothing). The compressed bytes depend only on the chunk's voxels.
  std::uint64_t writeChunk(const std::array<std::int64_t, 3>& chunk, const void* data) const;
  // Reads a chunk into `out` (chunkBytes() bytes): false, with `out` set to the fill value, when
  // it is not stored. Throws InputError for a chunk that does not decompress to its size.
  bool readChunk(const std::array<std::int64_t, 3>& chunk, void* out) const;
};

// NumPy's type string of a voxel type ("|u1", "<u2", "<i2", "<u4", "<f4").
std::string_view zarrDtype(VoxelType t);

}  // namespace angiosynth
