#include "score/skeleton.hpp"

#include <array>
#include <cstdlib>
#include <vector>

namespace angiosynth {
namespace {

// A 3×3×3 neighbourhood, n[(dx+1)·9 + (dy+1)·3 + (dz+1)], the centre at 13.
using Neighbourhood = std::array<std::uint8_t, 27>;
constexpr int at(int dx, int dy, int dz) { return (dx + 1) * 9 + (dy + 1) * 3 + (dz + 1); }

// 8 × the Euler characteristic contributed by one lattice vertex of the union of closed voxel
// cubes (26-connectivity), from the 8 cubes around it, c[a][b][d] with a, b, d the sides:
// 8·[vertex] − 4·(edges at it) + 2·(faces at it) − cubes; summed over all vertices this is 8χ.
int vertexTerm(const int c[2][2][2]) {
  int cubes = 0, edges = 0, faces = 0;
  for (int a = 0; a < 2; ++a)
    for (int b = 0; b < 2; ++b)
      for (int d = 0; d < 2; ++d) cubes += c[a][b][d];
  for (int s = 0; s < 2; ++s) {
    edges += (c[s][0][0] | c[s][0][1] | c[s][1][0] | c[s][1][1]);  // along x, side s
    edges += (c[0][s][0] | c[0][s][1] | c[1][s][0] | c[1][s][1]);  // along y
    edges += (c[0][0][s] | c[0][1][s] | c[1][0][s] | c[1][1][s]);  // along z
  }
  for (int s = 0; s < 2; ++s)
    for (int t = 0; t < 2; ++t) {
      faces += c[s][t][0] | c[s][t][1];  // in the x–y quadrant (s, t)
      faces += c[s][0][t] | c[s][1][t];  // x–z
      faces += c[0][s][t] | c[1][s][t];  // y–z
    }
  return 8 * (cubes > 0) - 4 * edges + 2 * faces - cubes;
}

// The change of a vertex's term when the cube at c[0][0][0] goes, for each configuration of the
// other seven (bit a + 2b + 4d), computed once.
const std::array<int, 256>& vertexChange() {
  static const std::array<int, 256> table = [] {
    std::array<int, 256> t{};
    for (int bits = 0; bits < 256; bits += 2) {
      int c[2][2][2];
      for (int q = 0; q < 8; ++q) c[q & 1][(q >> 1) & 1][q >> 2] = (bits >> q) & 1;
      c[0][0][0] = 1;
      const int with = vertexTerm(c);
      c[0][0][0] = 0;
      t[std::size_t(bits)] = with - vertexTerm(c);
    }
    return t;
  }();
  return table;
}

// Removing the centre leaves the Euler characteristic unchanged (Lee's condition 1): the
// change is the sum over the 8 vertices of the centre's cube.
bool eulerInvariant(const Neighbourhood& n) {
  const auto& table = vertexChange();
  int change = 0;
  for (int sx = -1; sx <= 1; sx += 2)
    for (int sy = -1; sy <= 1; sy += 2)
      for (int sz = -1; sz <= 1; sz += 2) {
        int bits = 0;
        for (int q = 1; q < 8; ++q) bits |= n[std::size_t(at((q & 1) * sx, ((q >> 1) & 1) * sy, (q >> 2) * sz))] << q;
        change += table[std::size_t(bits)];
      }
  return change == 0;
}

// The 26 neighbours of the centre form at most one 26-connected piece (Lee's conditions 2–3).
bool simplePoint(const Neighbourhood& n) {
  std::array<bool, 27> seen{};
  int pieces = 0;
  int stack[27];
  for (int start = 0; start < 27; ++start) {
    if (start == 13 || !n[std::size_t(start)] || seen[std::size_t(start)]) continue;
    if (++pieces > 1) return false;
    int top = 0;
    stack[top++] = start;
    seen[std::size_t(start)] = true;
    while (top) {
      const int q = stack[--top];
      const int qx = q / 9 - 1, qy = (q / 3) % 3 - 1, qz = q % 3 - 1;
      for (int r = 0; r < 27; ++r) {
        if (r == 13 || !n[std::size_t(r)] || seen[std::size_t(r)]) continue;
        if (std::abs(r / 9 - 1 - qx) <= 1 && std::abs((r / 3) % 3 - 1 - qy) <= 1 && std::abs(r % 3 - 1 - qz) <= 1) {
          seen[std::size_t(r)] = true;
          stack[top++] = r;
        }
      }
    }
  }
  return true;
}

}  // namespace

Volume<std::uint8_t> skeletonize(const Volume<std::uint8_t>& v) {
  const auto& g = v.grid;
  // Padded by one background voxel, x outermost and z fastest: the scan order of
  // scikit-image on an (x, y, z) array.
  const std::int64_t NX = g.dims[0] + 2, NY = g.dims[1] + 2, NZ = g.dims[2] + 2;
  const auto idx = [&](std::int64_t x, std::int64_t y, std::int64_t z) { return (x * NY + y) * NZ + z; };
  std::vector<std::uint8_t> img(std::size_t(NX * NY * NZ), 0);
  std::vector<std::int64_t> fg;  // foreground voxels in scan order
  for (std::int64_t x = 0; x < g.dims[0]; ++x)
    for (std::int64_t y = 0; y < g.dims[1]; ++y)
      for (std::int64_t z = 0; z < g.dims[2]; ++z)
        if (v.at(x, y, z)) {
          img[std::size_t(idx(x + 1, y + 1, z + 1))] = 1;
          fg.push_back(idx(x + 1, y + 1, z + 1));
        }
  const std::int64_t step[3] = {NY * NZ, NZ, 1};
  const auto gather = [&](std::int64_t i, Neighbourhood& n) {
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) n[std::size_t(at(dx, dy, dz))] = img[std::size_t(i + dx * step[0] + dy * step[1] + dz * step[2])];
  };
  // Borders in scikit-image's order: y−1, y+1, z+1, z−1, x+1, x−1 (its W, E, S, N, U, B); a
  // volume one voxel thick along x is 2D there and takes the first four only.
  const std::int64_t borders[6] = {-step[1], step[1], step[2], -step[2], step[0], -step[0]};
  const int num_borders = g.dims[0] == 1 ? 4 : 6;
  std::vector<std::int64_t> candidates;
  Neighbourhood n;
  for (int unchanged = 0; unchanged < num_borders;) {
    unchanged = 0;
    for (int b = 0; b < num_borders; ++b) {
      candidates.clear();
      for (const auto i : fg) {
        if (img[std::size_t(i)] != 1 || img[std::size_t(i + borders[b])] != 0) continue;
        gather(i, n);
        int count = 0;
        for (auto x : n) count += x;
        if (count == 2 || !eulerInvariant(n) || !simplePoint(n)) continue;  // an endpoint, or not deletable
        candidates.push_back(i);
      }
      bool changed = false;
      for (const auto i : candidates) {  // re-checked one by one: removals so far count
        gather(i, n);
        if (simplePoint(n)) img[std::size_t(i)] = 0, changed = true;
      }
      unchanged += !changed;
    }
    std::erase_if(fg, [&](std::int64_t i) { return img[std::size_t(i)] == 0; });
  }
  Volume<std::uint8_t> out(g);
  for (std::int64_t x = 0; x < g.dims[0]; ++x)
    for (std::int64_t y = 0; y < g.dims[1]; ++y)
      for (std::int64_t z = 0; z < g.dims[2]; ++z) out.at(x, y, z) = img[std::size_t(idx(x + 1, y + 1, z + 1))];
  return out;
}

}  // namespace angiosynth
