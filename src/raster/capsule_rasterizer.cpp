#include "raster/capsule_rasterizer.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "raster/vessel_capsule.hpp"

namespace angiosynth {
namespace {

// sd[q] = min(sd[q], the capsule's signedDistance at c + (ox, oy, oz)[q]) for a cylinder: the
// same arithmetic in the same order, written over arrays so that it vectorises.
// Wider vectors where the processor has them (chosen at run time); no FMA contraction (not
// enabled by "avx2"), so every lane computes the same IEEE value as the baseline build.
__attribute__((target_clones("avx2", "default"))) void cylinderDistances(const Capsule& cap, const Vec3& c, const double* ox, const double* oy,
                                                                         const double* oz, int n, double half_var, double* sd) {
  const double ax = cap.a.x, ay = cap.a.y, az = cap.a.z, dx = cap.d.x, dy = cap.d.y, dz = cap.d.z, inv = cap.inv_len2, r = cap.r;
  const double k_side = half_var * (1.0 / r), k_cap = half_var * (2.0 / r);
  if (!(inv > 0)) {  // a sphere
    for (int q = 0; q < n; ++q) {
      const double px = c.x + ox[q] - ax, py = c.y + oy[q] - ay, pz = c.z + oz[q] - az;
      const double v = std::sqrt(px * px + py * py + pz * pz) - r + k_cap;
      sd[q] = std::min(sd[q], v);
    }
    return;
  }
  for (int q = 0; q < n; ++q) {
    const double px = c.x + ox[q] - ax, py = c.y + oy[q] - ay, pz = c.z + oz[q] - az;
    const double u = (px * dx + py * dy + pz * dz) * inv;
    const double t = u < 0 ? 0 : (u > 1 ? 1 : u);
    const double qx = px - dx * t, qy = py - dy * t, qz = pz - dz * t;
    const double v = std::sqrt(qx * qx + qy * qy + qz * qz) - r + (t == u ? k_side : k_cap);
    sd[q] = std::min(sd[q], v);
  }
}

}  // namespace

double brickPairBound(const VascularTree& tree, const VolumeGrid& g) {
  double total = 0;
  for (std::int32_t s = 1; s < tree.nodeCount(); ++s) {
    if (tree.isRoot(s)) continue;
    const Vec3 a = tree.position[tree.parent[s]], b = tree.position[s];
    double n = 1;
    for (int ax = 0; ax < 3; ++ax) {
      const double extent = (std::abs(a[ax] - b[ax]) + 2 * tree.maxRadius(s)) / g.spacing_mm[ax] + 2;
      n *= std::min(extent / kBrick + 1, (g.dims[ax] + kBrick - 1.0) / kBrick);
    }
    total += n;
  }
  return total;
}

std::vector<std::int32_t> treeSegments(const VascularTree& tree) {
  std::vector<std::int32_t> out;
  out.reserve(std::size_t(std::max(0, tree.nodeCount() - 1)));
  for (std::int32_t s = 1; s < tree.nodeCount(); ++s)
    if (!tree.isRoot(s)) out.push_back(s);
  return out;
}

BrickBins binSegments(const VascularTree& tree, const VolumeGrid& g) { return binSegments(tree, g, VoxelWindow::whole(g), treeSegments(tree)); }

BrickBins binSegments(const VascularTree& tree, const VolumeGrid& g, const VoxelWindow& window, std::span<const std::int32_t> segments) {
  BrickBins bins;
  for (int ax = 0; ax < 3; ++ax) bins.bricks[ax] = (g.dims[ax] + kBrick - 1) / kBrick;
  const Vec3 sp = g.spacing_mm;
  const double brick_half_diag = 0.5 * kBrick * std::sqrt(dot(sp, sp));
  int window_lo[3], window_hi[3];  // bricks
  for (int ax = 0; ax < 3; ++ax) {
    window_lo[ax] = static_cast<int>(std::max<std::int64_t>(0, window.lo[ax]) / kBrick);
    window_hi[ax] = static_cast<int>((std::min<std::int64_t>(g.dims[ax], window.hi[ax]) + kBrick - 1) / kBrick) - 1;
  }
  std::vector<std::pair<std::int64_t, std::int32_t>> pairs;
  for (const std::int32_t s : segments) {
    const Vec3 a = tree.position[tree.parent[s]], b = tree.position[s];
    const double r = tree.maxRadius(s);
    // Voxel x (cube [x−½, x+½] in index units) can touch the capsule's box if
    // x ∈ [⌈min − r/s − ½⌉, ⌊max + r/s + ½⌋]; bricks hold voxels 8b … 8b+7.
    int lo[3], hi[3];
    bool outside = false;
    for (int ax = 0; ax < 3; ++ax) {
      const double ia = (a[ax] - g.origin_mm[ax]) / sp[ax], ib = (b[ax] - g.origin_mm[ax]) / sp[ax];
      const double rr = r / sp[ax] + 0.5;
      const double x_lo = std::max(0.0, std::ceil(std::min(ia, ib) - rr));
      const double x_hi = std::min(double(g.dims[ax] - 1), std::floor(std::max(ia, ib) + rr));
      if (x_hi < x_lo) outside = true;
      lo[ax] = static_cast<int>(x_lo) / kBrick;
      hi[ax] = static_cast<int>(std::max(x_lo, x_hi)) / kBrick;
    }
    if (outside) continue;
    // Whether a segment is tested against each brick's centre depends on its whole box, not on
    // the window, so a window keeps exactly the whole grid's pairs.
    const bool big = (hi[0] - lo[0] + 1) * (hi[1] - lo[1] + 1) * (hi[2] - lo[2] + 1) > 8;
    for (int ax = 0; ax < 3; ++ax) {
      lo[ax] = std::max(lo[ax], window_lo[ax]);
      hi[ax] = std::min(hi[ax], window_hi[ax]);
      outside |= hi[ax] < lo[ax];
    }
    if (outside) continue;
    for (int k = lo[2]; k <= hi[2]; ++k)
      for (int j = lo[1]; j <= hi[1]; ++j)
        for (int i = lo[0]; i <= hi[0]; ++i) {
          if (big) {
            // Brick centre = centre of its voxels (i·8 + 3.5).
            const Vec3 c = g.centre(0, 0, 0) + Vec3((i * kBrick + 3.5) * sp.x, (j * kBrick + 3.5) * sp.y, (k * kBrick + 3.5) * sp.z);
            if (pointSegmentDistance(c, a, b) > r + brick_half_diag) continue;
          }
          pairs.emplace_back(i + std::int64_t(bins.bricks[0]) * (j + std::int64_t(bins.bricks[1]) * k), s);
        }
  }
  std::sort(pairs.begin(), pairs.end());
  for (const auto& [brick, s] : pairs) {
    if (bins.brick_ids.empty() || bins.brick_ids.back() != brick) {
      bins.brick_ids.push_back(brick);
      bins.segments.emplace_back();
    }
    bins.segments.back().push_back(s);
  }
  return bins;
}

void rasterizeBricks(const VascularTree& tree, const VolumeGrid& g, const BrickBins& bins, const RasterOptions& opt, const BrickVisitor& visit) {
  const int S = std::max(1, opt.supersampling);
  const Vec3 sp = g.spacing_mm;
  // A voxel lies wholly inside (outside) a capsule if its centre is deeper (farther) than the
  // voxel's half diagonal from the capsule surface.
  const double half_diag = 0.5 * std::sqrt(dot(sp, sp));
  std::vector<Vec3> offsets;
  for (int c = 0; c < S; ++c)
    for (int b = 0; b < S; ++b)
      for (int a = 0; a < S; ++a) offsets.emplace_back(((a + 0.5) / S - 0.5) * sp.x, ((b + 0.5) / S - 0.5) * sp.y, ((c + 0.5) / S - 0.5) * sp.z);
  const double inv_samples = 1.0 / double(offsets.size());
  const double sub_width = std::cbrt(sp.x * sp.y * sp.z) / S;  // subvoxel edge
  const double inv_sub_width = 1.0 / sub_width;
  const double half_var = sub_width * sub_width / 24.0;  // σ²/2 with σ² = w²/12
  std::vector<double> ox, oy, oz;
  for (const Vec3& o : offsets) ox.push_back(o.x), oy.push_back(o.y), oz.push_back(o.z);
  constexpr int kVoxels = kBrick * kBrick * kBrick;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, bins.brick_ids.size(), 16), [&](const tbb::blocked_range<std::size_t>& range) {
    std::vector<Capsule> caps, near;
    float fraction[kVoxels];
    std::uint32_t instance[kVoxels];
    double best[kVoxels];
    bool full[kVoxels];
    int count[kVoxels + 1];
    // (voxel, capsule) pairs of capsules whose surface may cross the voxel, in capsule order,
    // then grouped by voxel (counting sort: each voxel's capsules stay in capsule order).
    std::vector<std::pair<std::uint16_t, std::int32_t>> pairs;
    std::vector<std::int32_t> grouped;
    std::vector<double> sd(offsets.size());
    for (std::size_t bi = range.begin(); bi != range.end(); ++bi) {
      const std::int64_t brick = bins.brick_ids[bi];
      const std::int64_t bx = brick % bins.bricks[0], by = (brick / bins.bricks[0]) % bins.bricks[1],
                         bz = brick / (std::int64_t(bins.bricks[0]) * bins.bricks[1]);
      const std::int64_t base[3] = {bx * kBrick, by * kBrick, bz * kBrick};
      caps.clear();
      for (auto s : bins.segments[bi]) caps.push_back(capsuleOf(tree, s));
      std::fill(fraction, fraction + kVoxels, 0.0f);
      std::fill(instance, instance + kVoxels, 0u);
      std::fill(best, best + kVoxels, 1e300);
      std::fill(full, full + kVoxels, false);
      pairs.clear();
      // A capsule can reach only the voxels whose centres lie in its box grown by its radius and
      // the half diagonal (a hair more, so rounding never drops one): visit those alone. Each
      // voxel sees its capsules in the same order as a scan of all of them would.
      for (std::size_t ci = 0; ci < caps.size(); ++ci) {
        const Capsule& cap = caps[ci];
        const double reach = (cap.r + half_diag) * (1 + 1e-9) + 1e-12;
        std::int64_t lo[3], hi[3];
        bool empty = false;
        for (int ax = 0; ax < 3; ++ax) {
          const double a = cap.a[ax], b = a + cap.d[ax];
          const double i0 = std::ceil((std::min(a, b) - reach - g.origin_mm[ax]) / sp[ax]);
          const double i1 = std::floor((std::max(a, b) + reach - g.origin_mm[ax]) / sp[ax]);
          lo[ax] = static_cast<std::int64_t>(std::max(i0, double(std::max<std::int64_t>(base[ax], 0))));
          hi[ax] = static_cast<std::int64_t>(std::min(i1, double(std::min<std::int64_t>(base[ax] + kBrick, g.dims[ax]) - 1)));
          empty |= hi[ax] < lo[ax];
        }
        if (empty) continue;
        for (std::int64_t z = lo[2]; z <= hi[2]; ++z)
          for (std::int64_t y = lo[1]; y <= hi[1]; ++y)
            for (std::int64_t x = lo[0]; x <= hi[0]; ++x) {
              const int v = int((x - base[0]) + kBrick * ((y - base[1]) + kBrick * (z - base[2])));
              const double depth = cap.depth(g.centre(x, y, z));  // < 0 inside
              if (depth >= half_diag) continue;
              if (depth < best[v]) best[v] = depth, instance[v] = cap.id;
              if (depth <= -half_diag) full[v] = true;
              pairs.emplace_back(std::uint16_t(v), std::int32_t(ci));
            }
      }
      std::fill(count, count + kVoxels + 1, 0);
      for (const auto& pr : pairs) ++count[pr.first + 1];
      for (int v = 0; v < kVoxels; ++v) count[v + 1] += count[v];
      grouped.resize(pairs.size());
      {
        int fill[kVoxels];
        std::copy(count, count + kVoxels, fill);
        for (const auto& pr : pairs) grouped[std::size_t(fill[pr.first]++)] = pr.second;
      }
      for (int v = 0; v < kVoxels; ++v) {
        if (full[v]) {
          fraction[v] = 1;
          continue;
        }
        if (count[v] == count[v + 1]) continue;
        const int i = v % kBrick, j = (v / kBrick) % kBrick, k = v / (kBrick * kBrick);
        const Vec3 c = g.centre(base[0] + i, base[1] + j, base[2] + k);
        near.clear();
        for (int q = count[v]; q < count[v + 1]; ++q) near.push_back(caps[std::size_t(grouped[std::size_t(q)])]);
        // Each subvoxel counts by its signed distance to the vessel surface through a linear
        // ramp of its width w (the same second moment, w²/12, as the exact cube coverage in
        // any orientation), with the surface moved in by σ²κ/2 (κ = 1/r on the cylinder,
        // 2/r on the caps): the level shift that smoothing causes on a curved surface.
        // Second-order accurate, where 0/1 samples alias on thin vessels.
        // Capsule by capsule over all samples (the minimum is the same in any order; the sum
        // below runs in sample order as before), so the cylinder loop vectorises.
        std::fill(sd.begin(), sd.end(), 1e300);
        for (const auto& cap : near) {
          if (cap.cone) {
            for (std::size_t q = 0; q < offsets.size(); ++q) sd[q] = std::min(sd[q], cap.signedDistance(c + offsets[q], half_var));
          } else {
            cylinderDistances(cap, c, ox.data(), oy.data(), oz.data(), int(offsets.size()), half_var, sd.data());
          }
        }
        double inside = 0;
        for (std::size_t q = 0; q < offsets.size(); ++q) inside += std::clamp(0.5 - sd[q] * inv_sub_width, 0.0, 1.0);
        fraction[v] = static_cast<float>(std::min(1.0, inside * inv_samples));
        if (inside == 0) instance[v] = 0;
      }
      visit(brick, fraction, instance);
    }
  });
}

void rasterizeDense(const VascularTree& tree, const VolumeGrid& g, const RasterOptions& opt, Volume<float>& fraction,
                    Volume<std::uint32_t>& instances) {
  fraction = Volume<float>(g, 0.0f);
  instances = Volume<std::uint32_t>(g, 0u);
  const BrickBins bins = binSegments(tree, g);
  std::array<std::int32_t, 3> nb = bins.bricks;
  rasterizeBricks(tree, g, bins, opt, [&](std::int64_t brick, const float* f, const std::uint32_t* id) {
    const std::int64_t bx = brick % nb[0], by = (brick / nb[0]) % nb[1], bz = brick / (std::int64_t(nb[0]) * nb[1]);
    for (int k = 0; k < kBrick; ++k)
      for (int j = 0; j < kBrick; ++j)
        for (int i = 0; i < kBrick; ++i) {
          const std::int64_t x = bx * kBrick + i, y = by * kBrick + j, z = bz * kBrick + k;
          if (!g.contains(x, y, z)) continue;
          const int v = i + kBrick * (j + kBrick * k);
          if (f[v] == 0) continue;  // untouched pages stay unallocated
          fraction.at(x, y, z) = f[v];
          instances.at(x, y, z) = id[v];
        }
  });
}

}  // namespace angiosynth
