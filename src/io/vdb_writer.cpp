// .vdb files through libangiosynth_vdb.so, loaded on the first call (see vdb_module_api.hpp).
#include "io/vdb_writer.hpp"

#include <dlfcn.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <memory>
#include <mutex>
#include <vector>

#include "core/error.hpp"
#include "io/vdb_module_api.hpp"

namespace angiosynth {
namespace {

// Beside the program (a build or an install's bin/), else the library path (lib/).
const AngiosynthVdbApi* loadModule(const std::filesystem::path& for_file) {
  static const AngiosynthVdbApi* api = nullptr;
  static std::string failure;
  static std::once_flag once;
  std::call_once(once, [] {
    std::vector<std::string> tried;
    std::error_code ec;
    const auto exe = std::filesystem::read_symlink("/proc/self/exe", ec);
    std::vector<std::string> names;
    if (!ec) {
      names.push_back((exe.parent_path() / "libangiosynth_vdb.so").string());
      names.push_back((exe.parent_path().parent_path() / "lib" / "libangiosynth_vdb.so").string());
    }
    names.push_back("libangiosynth_vdb.so");
    for (const auto& n : names) {
      void* h = dlopen(n.c_str(), RTLD_NOW | RTLD_LOCAL);
      if (!h) {
        tried.push_back(dlerror());
        continue;
      }
      auto entry = reinterpret_cast<const AngiosynthVdbApi* (*)()>(dlsym(h, "angiosynth_vdb_api"));
      if (entry && entry()->version == kAngiosynthVdbApiVersion) {
        api = entry();
        return;
      }
      tried.push_back(n + ": not this version's module");
    }
    failure = "the OpenVDB module libangiosynth_vdb.so (built beside the program) could not be loaded";
    for (const auto& t : tried) failure += "; " + t;
  });
  if (!api) throw InputError(for_file.string(), 0, "cannot write: " + failure);
  return api;
}

}  // namespace

std::uint64_t sparseRasterBytes(const BrickBins& bins) {
  // A float leaf and an int leaf (2 KiB each plus masks), the bricks' rasterised values
  // (4 KiB each) until they are handed over, and the bins themselves.
  std::uint64_t seg_refs = 0;
  for (const auto& s : bins.segments) seg_refs += s.size();
  return bins.brick_ids.size() * (2 * (512 * 4 + 128) + 64 + 512 * 8) + seg_refs * 4 + bins.brick_ids.size() * 32;
}

static_assert(kBrick == 8, "the module's leaves are 8³ bricks (OpenVDB's leaf size)");

VdbReport writeVdb(const std::filesystem::path& file, const VascularTree& tree, const VolumeGrid& g, const BrickBins& bins,
                   const RasterOptions& opt) {
  const AngiosynthVdbApi* api = loadModule(file);
  constexpr int n = kBrick * kBrick * kBrick;
  struct Brick {
    std::array<float, n> fraction;
    std::array<std::uint32_t, n> ids;
  };
  std::vector<std::unique_ptr<Brick>> bricks(bins.brick_ids.size());
  rasterizeBricks(tree, g, bins, opt, [&](std::int64_t brick, const float* f, const std::uint32_t* id) {
    if (std::all_of(f, f + n, [](float v) { return v == 0; })) return;
    const std::size_t bi = std::lower_bound(bins.brick_ids.begin(), bins.brick_ids.end(), brick) - bins.brick_ids.begin();
    auto b = std::make_unique<Brick>();
    std::copy(f, f + n, b->fraction.begin());
    std::copy(id, id + n, b->ids.begin());
    bricks[bi] = std::move(b);
  });
  std::unique_ptr<void, void (*)(void*)> w(api->create(), api->destroy);
  // Leaves in brick order: the tree, and so the file, does not depend on threads.
  const auto nb = bins.bricks;
  for (std::size_t bi = 0; bi < bricks.size(); ++bi) {
    if (!bricks[bi]) continue;
    const std::int64_t brick = bins.brick_ids[bi];
    const std::int64_t bx = brick % nb[0], by = (brick / nb[0]) % nb[1], bz = brick / (std::int64_t(nb[0]) * nb[1]);
    api->add_leaf(w.get(), std::int32_t(bx * kBrick), std::int32_t(by * kBrick), std::int32_t(bz * kBrick), bricks[bi]->fraction.data(),
                  bricks[bi]->ids.data());
    bricks[bi].reset();
  }
  const double spacing[3] = {g.spacing_mm.x, g.spacing_mm.y, g.spacing_mm.z}, origin[3] = {g.origin_mm.x, g.origin_mm.y, g.origin_mm.z};
  VdbReport report;
  char error[512] = "";
  if (api->write(w.get(), file.c_str(), spacing, origin, &report.leaves, &report.active_voxels, error, sizeof error) != 0)
    throw InputError(file.string(), 0, std::string("cannot write: ") + error);
  return report;
}

}  // namespace angiosynth
