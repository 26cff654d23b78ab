#pragma once
// The C interface of the OpenVDB module (libangiosynth_vdb.so). OpenVDB's many symbols cost
// every run tens of milliseconds of dynamic linking; only runs that write .vdb load it.
#include <cstddef>
#include <cstdint>

extern "C" {

struct AngiosynthVdbApi {
  int version;  // kAngiosynthVdbApiVersion
  // A writer for one file: leaves (8³ bricks at their index origin, fraction and segment id per
  // voxel, x fastest) added in a fixed order, then written with the grid's spacing and origin (mm).
  void* (*create)();
  void (*add_leaf)(void* w, std::int32_t x, std::int32_t y, std::int32_t z, const float* fraction, const std::uint32_t* ids);
  // 0 on success; else the reason in `error`.
  int (*write)(void* w, const char* file, const double spacing[3], const double origin[3], std::int64_t* leaves, std::int64_t* active_voxels,
               char* error, std::size_t error_size);
  void (*destroy)(void* w);
};

const AngiosynthVdbApi* angiosynth_vdb_api();
}

constexpr int kAngiosynthVdbApiVersion = 1;
