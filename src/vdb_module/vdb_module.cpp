// The only translation unit that includes OpenVDB (heavy headers).
#include "io/vdb_writer.hpp"

#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>

#include <algorithm>
#include <mutex>

#include "core/error.hpp"

namespace angiosynth {

std::uint64_t sparseRasterBytes(const BrickBins& bins) {
  // A float leaf and an int leaf (2 KiB each plus masks), and the bins themselves.
  std::uint64_t seg_refs = 0;
  for (const auto& s : bins.segments) seg_refs += s.size();
  return bins.brick_ids.size() * (2 * (512 * 4 + 128) + 64) + seg_refs * 4 + bins.brick_ids.size() * 32;
}

VdbReport writeVdb(const std::filesystem::path& file, const VascularTree& tree, const VolumeGrid& g, const BrickBins& bins,
                   const RasterOptions& opt) {
  static std::once_flag init;
  std::call_once(init, [] { openvdb::initialize(); });
  using FloatLeaf = openvdb::FloatTree::LeafNodeType;
  using IntLeaf = openvdb::Int32Tree::LeafNodeType;
  std::vector<std::unique_ptr<FloatLeaf>> fleaves(bins.brick_ids.size());
  std::vector<std::unique_ptr<IntLeaf>> ileaves(bins.brick_ids.size());
  const auto nb = bins.bricks;
  rasterizeBricks(tree, g, bins, opt, [&](std::int64_t brick, const float* f, const std::uint32_t* id) {
    if (std::all_of(f, f + kBrick * kBrick * kBrick, [](float v) { return v == 0; })) return;
    const std::size_t bi = std::lower_bound(bins.brick_ids.begin(), bins.brick_ids.end(), brick) - bins.brick_ids.begin();
    const std::int64_t bx = brick % nb[0], by = (brick / nb[0]) % nb[1], bz = brick / (std::int64_t(nb[0]) * nb[1]);
    const openvdb::Coord origin(int(bx * kBrick), int(by * kBrick), int(bz * kBrick));
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
    fleaves[bi] = std::move(fl);
    ileaves[bi] = std::move(il);
  });
  auto fgrid = openvdb::FloatGrid::create(0.0f);
  auto igrid = openvdb::Int32Grid::create(0);
  // Attach leaves in brick order: the tree, and so the file, does not depend on threads.
  VdbReport report;
  for (std::size_t bi = 0; bi < fleaves.size(); ++bi) {
    if (!fleaves[bi]) continue;
    ++report.leaves;
    report.active_voxels += fleaves[bi]->onVoxelCount();
    fgrid->tree().addLeaf(fleaves[bi].release());
    if (ileaves[bi]->onVoxelCount() > 0) igrid->tree().addLeaf(ileaves[bi].release());
  }
  // OpenVDB matrices act on row vectors: scale on the diagonal, translation in the last row.
  openvdb::math::Mat4d m = openvdb::math::Mat4d::identity();
  m(0, 0) = g.spacing_mm.x;
  m(1, 1) = g.spacing_mm.y;
  m(2, 2) = g.spacing_mm.z;
  m(3, 0) = g.origin_mm.x;
  m(3, 1) = g.origin_mm.y;
  m(3, 2) = g.origin_mm.z;
  auto transform = openvdb::math::Transform::createLinearTransform(m);
  for (openvdb::GridBase::Ptr grid : {openvdb::GridBase::Ptr(fgrid), openvdb::GridBase::Ptr(igrid)}) {
    grid->setTransform(transform->copy());
    grid->insertMeta("units", openvdb::StringMetadata("mm, RAS"));
  }
  fgrid->setName("fraction");
  fgrid->setGridClass(openvdb::GRID_FOG_VOLUME);
  igrid->setName("instances");
  try {
    openvdb::io::File out(file.string());
    out.write({fgrid, igrid});
    out.close();
  } catch (const std::exception& e) {
    throw InputError(file.string(), 0, std::string("cannot write: ") + e.what());
  }
  return report;
}

}  // namespace angiosynth
