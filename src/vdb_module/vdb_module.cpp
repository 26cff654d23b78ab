// libangiosynth_vdb.so: the only code that includes or links OpenVDB (heavy headers, and a
// library whose symbols slow every program start); the main program loads it when asked for .vdb.
#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>

#include <cstring>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "io/vdb_module_api.hpp"

namespace {

constexpr int kBrick = 8;

struct Writer {
  openvdb::FloatGrid::Ptr fraction = openvdb::FloatGrid::create(0.0f);
  openvdb::Int32Grid::Ptr instances = openvdb::Int32Grid::create(0);
  std::int64_t leaves = 0, active = 0;
};

void* create() {
  static std::once_flag init;
  std::call_once(init, [] { openvdb::initialize(); });
  return new Writer;
}

void addLeaf(void* p, std::int32_t x, std::int32_t y, std::int32_t z, const float* f, const std::uint32_t* id) {
  auto& w = *static_cast<Writer*>(p);
  using FloatLeaf = openvdb::FloatTree::LeafNodeType;
  using IntLeaf = openvdb::Int32Tree::LeafNodeType;
  const openvdb::Coord origin(x, y, z);
  auto fl = std::make_unique<FloatLeaf>(origin, 0.0f, false);
  auto il = std::make_unique<IntLeaf>(origin, 0, false);
  for (int k = 0; k < kBrick; ++k)
    for (int j = 0; j < kBrick; ++j)
      for (int i = 0; i < kBrick; ++i) {
        const int v = i + kBrick * (j + kBrick * k);
        if (f[v] == 0) continue;
        const openvdb::Coord c = origin.offsetBy(i, j, k);
        fl->setValueOn(c, f[v]);
        if (f[v] >= 0.5f) il->setValueOn(c, static_cast<std::int32_t>(id[v]));
      }
  ++w.leaves;
  w.active += fl->onVoxelCount();
  w.fraction->tree().addLeaf(fl.release());
  if (il->onVoxelCount() > 0) w.instances->tree().addLeaf(il.release());
}

int write(void* p, const char* file, const double spacing[3], const double origin[3], std::int64_t* leaves, std::int64_t* active, char* error,
          std::size_t error_size) {
  auto& w = *static_cast<Writer*>(p);
  // OpenVDB matrices act on row vectors: scale on the diagonal, translation in the last row.
  openvdb::math::Mat4d m = openvdb::math::Mat4d::identity();
  for (int a = 0; a < 3; ++a) m(a, a) = spacing[a], m(3, a) = origin[a];
  auto transform = openvdb::math::Transform::createLinearTransform(m);
  for (openvdb::GridBase::Ptr grid : {openvdb::GridBase::Ptr(w.fraction), openvdb::GridBase::Ptr(w.instances)}) {
    grid->setTransform(transform->copy());
    grid->insertMeta("units", openvdb::StringMetadata("mm, RAS"));
  }
  w.fraction->setName("fraction");
  w.fraction->setGridClass(openvdb::GRID_FOG_VOLUME);
  w.instances->setName("instances");
  *leaves = w.leaves;
  *active = w.active;
  try {
    openvdb::io::File out(file);
    out.write({w.fraction, w.instances});
    out.close();
  } catch (const std::exception& e) {
    std::snprintf(error, error_size, "%s", e.what());
    return 1;
  }
  return 0;
}

void destroy(void* p) { delete static_cast<Writer*>(p); }

}  // namespace

extern "C" const AngiosynthVdbApi* angiosynth_vdb_api() {
  static const AngiosynthVdbApi api{kAngiosynthVdbApiVersion, &create, &addLeaf, &write, &destroy};
  return &api;
}
