#include "io/zarr_array.hpp"

#include <blosc.h>
#include <zlib.h>

#include <algorithm>
#include <cstring>
#include <fstream>
#include <iterator>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/error.hpp"
#include "files/atomic_file.hpp"

namespace angiosynth {
namespace {

constexpr ZarrCodec kCodecs[] = {ZarrCodec::Blosc, ZarrCodec::Zlib};

// f(T{}) with T the voxel type's C++ type.
template <class F>
decltype(auto) withVoxelType(VoxelType t, F&& f) {
  switch (t) {
    case VoxelType::UInt8: return f(std::uint8_t{});
    case VoxelType::Int16: return f(std::int16_t{});
    case VoxelType::UInt16: return f(std::uint16_t{});
    case VoxelType::UInt32: return f(std::uint32_t{});
    case VoxelType::Float32: break;
  }
  return f(float{});
}

bool isFill(const void* data, std::size_t bytes, VoxelType t, double fill) {
  return withVoxelType(t, [&](auto zero) {
    using T = decltype(zero);
    const T* v = static_cast<const T*>(data);
    const T f = static_cast<T>(fill);
    return std::all_of(v, v + bytes / sizeof(T), [&](const T& x) { return std::memcmp(&x, &f, sizeof(T)) == 0; });
  });
}

void fillChunk(void* out, std::size_t bytes, VoxelType t, double fill) {
  withVoxelType(t, [&](auto zero) {
    using T = decltype(zero);
    T* v = static_cast<T*>(out);
    std::fill(v, v + bytes / sizeof(T), static_cast<T>(fill));
  });
}

}  // namespace

const ZarrCodec* findZarrCodec(std::string_view name) {
  for (const ZarrCodec& c : kCodecs)
    if (zarrCodecName(c) == name) return &c;
  return nullptr;
}

std::string_view zarrCodecName(ZarrCodec c) { return c == ZarrCodec::Blosc ? "blosc" : "zlib"; }

std::string_view zarrDtype(VoxelType t) {
  switch (t) {
    case VoxelType::UInt8: return "|u1";
    case VoxelType::Int16: return "<i2";
    case VoxelType::UInt16: return "<u2";
    case VoxelType::UInt32: return "<u4";
    case VoxelType::Float32: return "<f4";
  }
  return "<f4";
}

std::array<std::int64_t, 3> ZarrArray::chunkGrid() const {
  std::array<std::int64_t, 3> n{};
  for (int a = 0; a < 3; ++a) n[a] = (shape[a] + chunks[a] - 1) / chunks[a];
  return n;
}

std::filesystem::path ZarrArray::chunkPath(const std::array<std::int64_t, 3>& c) const {
  return dir / std::to_string(c[0]) / std::to_string(c[1]) / std::to_string(c[2]);
}

std::string ZarrArray::metadata() const {
  nlohmann::ordered_json j;
  j["zarr_format"] = 2;
  j["shape"] = shape;
  j["chunks"] = chunks;
  j["dtype"] = zarrDtype(type);
  if (codec == ZarrCodec::Blosc)
    j["compressor"] = {{"id", "blosc"}, {"cname", "lz4"}, {"clevel", level}, {"shuffle", 1}, {"blocksize", 0}};
  else
    j["compressor"] = {{"id", "zlib"}, {"level", level}};
  if (type == VoxelType::Float32)
    j["fill_value"] = fill;
  else
    j["fill_value"] = static_cast<std::int64_t>(fill);
  j["order"] = "C";
  j["filters"] = nullptr;
  j["dimension_separator"] = "/";  // nested chunk directories, as OME-NGFF 0.4 requires
  return j.dump(2) + "\n";
}

void ZarrArray::writeMetadata() const {
  std::filesystem::create_directories(dir);
  writeFileAtomically(dir / ".zarray", metadata());
}

std::uint64_t ZarrArray::writeChunk(const std::array<std::int64_t, 3>& chunk, const void* data) const {
  const std::size_t bytes = chunkBytes();
  if (isFill(data, bytes, type, fill)) return 0;
  // Kept per thread: a buffer the size of a chunk, made afresh, takes a page fault per page.
  thread_local std::string packed;
  if (codec == ZarrCodec::Blosc) {
    packed.resize(bytes + BLOSC_MAX_OVERHEAD);
    // One internal thread: chunks and channels already run in parallel, and the stream does not
    // depend on the thread count.
    const int n = blosc_compress_ctx(level, BLOSC_SHUFFLE, voxelBytes(type), bytes, data, packed.data(), packed.size(), BLOSC_LZ4_COMPNAME, 0, 1);
    if (n <= 0) throw InputError(chunkPath(chunk).string(), 0, "Blosc could not compress the chunk (" + std::to_string(n) + ")");
    packed.resize(std::size_t(n));
  } else {
    uLongf n = compressBound(uLong(bytes));
    packed.resize(n);
    if (compress2(reinterpret_cast<Bytef*>(packed.data()), &n, static_cast<const Bytef*>(data), uLong(bytes), level) != Z_OK)
      throw InputError(chunkPath(chunk).string(), 0, "zlib could not compress the chunk");
    packed.resize(n);
  }
  const auto file = chunkPath(chunk);
  std::filesystem::create_directories(file.parent_path());
  writeFileAtomically(file, packed);
  return packed.size();
}

bool ZarrArray::readChunk(const std::array<std::int64_t, 3>& chunk, void* out) const {
  const std::size_t bytes = chunkBytes();
  const auto file = chunkPath(chunk);
  std::ifstream in(file, std::ios::binary);
  if (!in) {
    fillChunk(out, bytes, type, fill);
    return false;
  }
  const std::string packed((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  bool ok = false;
  if (codec == ZarrCodec::Blosc) {
    // The header is validated first (sizes consistent with the buffer): a damaged chunk is refused,
    // not decoded.
    std::size_t stored = 0;
    ok = packed.size() >= BLOSC_MIN_HEADER_LENGTH && blosc_cbuffer_validate(packed.data(), packed.size(), &stored) == 0 && stored == bytes &&
         blosc_decompress_ctx(packed.data(), out, bytes, 1) == int(bytes);
  } else {
    uLongf n = uLongf(bytes);
    ok = uncompress(static_cast<Bytef*>(out), &n, reinterpret_cast<const Bytef*>(packed.data()), uLong(packed.size())) == Z_OK && n == bytes;
  }
  if (!ok)
    throw InputError(file.string(), 0, "the chunk does not decompress to " + std::to_string(bytes) + " bytes; allowed: a chunk this array wrote");
  return true;
}

}  // namespace angiosynth
