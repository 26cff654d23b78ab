// Chunks of an OME-Zarr store read back, as the pyramid reads every chunk of the level below: the
// first byte picks the codec (bit 0: zlib, else Blosc) and the voxel type (the rest), the other
// bytes are the chunk's file. A chunk that does not decompress to its size is an InputError.
#include <filesystem>
#include <vector>

#include "fuzz_support.hpp"
#include "io/zarr_array.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace angiosynth;
  if (size == 0) return 0;
  constexpr VoxelType kTypes[] = {VoxelType::UInt8, VoxelType::Int16, VoxelType::UInt16, VoxelType::UInt32, VoxelType::Float32};
  ZarrArray a;
  a.dir = fuzz::scratchDir() / "array";
  a.shape = {8, 8, 8};
  a.chunks = {8, 8, 8};
  a.codec = data[0] & 1 ? ZarrCodec::Zlib : ZarrCodec::Blosc;
  a.type = kTypes[(data[0] >> 1) % 5];
  std::filesystem::create_directories(a.dir / "0" / "0");
  fuzz::writeInput(data + 1, size - 1, "array/0/0/0");
  std::vector<std::uint8_t> out(a.chunkBytes());
  return fuzz::expectOnlyInputErrors([&] {
    (void)a.readChunk({0, 0, 0}, out.data());
    // What the reader accepted round-trips through the writer.
    ZarrArray b = a;
    b.dir = fuzz::scratchDir() / "copy";
    std::vector<std::uint8_t> back(a.chunkBytes());
    if (b.writeChunk({0, 0, 0}, out.data()) > 0 && (!b.readChunk({0, 0, 0}, back.data()) || back != out)) __builtin_trap();
  });
}
