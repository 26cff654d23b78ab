#include "io/map_files.hpp"

#include <algorithm>

#include "core/error.hpp"
#include "core/memory.hpp"
#include "domain/demand_sampler.hpp"
#include "settings/param_checks.hpp"
#include "files/text_lines.hpp"

namespace angiosynth {
namespace {

struct Box {
  std::int32_t lo[3], hi[3];
};

std::array<std::int32_t, 3> readDims(const TextLine& l, const std::string& file, std::size_t words_expected, const std::string& what) {
  const auto w = splitWords(l.text);
  if (w.size() != words_expected)
    throw InputError(file, l.number,
                     "the first line of a " + what + " must be '" + (words_expected == 3 ? "DX DY DZ" : "DX DY DZ K") + "', got '" + l.text + "'");
  std::array<std::int32_t, 3> d{};
  for (int ax = 0; ax < 3; ++ax) {
    const auto v = parseInteger(w[ax], file, l.number, "map size");
    if (v < 1 || v > 100000) throw InputError(file, l.number, "map size " + w[ax] + " is out of range; allowed: 1 to 100000 voxels per axis");
    d[ax] = static_cast<std::int32_t>(v);
  }
  return d;
}

Box readBox(const TextLine& l, const std::string& file, const std::array<std::int32_t, 3>& dims) {
  const auto w = splitWords(l.text);
  if (w.size() != 6) throw InputError(file, l.number, "expected a box 'x0 y0 z0 x1 y1 z1' (6 whole numbers), got '" + l.text + "'");
  Box b{};
  for (int ax = 0; ax < 3; ++ax) {
    const auto lo = parseInteger(w[ax], file, l.number, "box corner"), hi = parseInteger(w[ax + 3], file, l.number, "box corner");
    b.lo[ax] = static_cast<std::int32_t>(std::clamp<std::int64_t>(lo, -1, dims[ax] + 1));  // out of range stays out of range
    b.hi[ax] = static_cast<std::int32_t>(std::clamp<std::int64_t>(hi, -1, dims[ax] + 1));
    if (lo < 0 || hi > dims[ax] || lo >= hi)
      throw InputError(file, l.number,
                       "box '" + l.text + "' lies outside the map or is empty; allowed: 0 <= x0 < x1 <= " + std::to_string(dims[0]) +
                           ", 0 <= y0 < y1 <= " + std::to_string(dims[1]) + ", 0 <= z0 < z1 <= " + std::to_string(dims[2]) + " (half-open boxes)");
  }
  return b;
}

template <class F>
void forBox(const DemandMap& m, const Box& b, F&& f) {
  for (std::int32_t k = b.lo[2]; k < b.hi[2]; ++k)
    for (std::int32_t j = b.lo[1]; j < b.hi[1]; ++j)
      for (std::int32_t i = b.lo[0]; i < b.hi[0]; ++i) f(m.flat(i, j, k));
}

}  // namespace

std::uint64_t growthBytesFor(std::int64_t voxels) {
  // Demand, supply index and ClearPaths' clearance (its one-voxel padding left out) per voxel.
  return static_cast<std::uint64_t>(voxels) * (sizeof(float) + sizeof(std::uint16_t) + sizeof(std::uint8_t)) + DemandSampler::bytesFor(voxels);
}

DemandMap loadDomain(const BoxMapSpec& sc, std::uint64_t memory_limit) {
  const std::string file = sc.demand_map.string();
  const auto lines = readTextLines(sc.demand_map, "oxygen-demand map");
  if (lines.empty()) throw InputError(file, 0, "empty oxygen-demand map; expected 'DX DY DZ' then box and value lines");
  DemandMap m;
  m.dims = readDims(lines[0], file, 3, "demand map");
  m.voxel_mm = sc.voxel_mm;
  const auto need = growthBytesFor(m.voxelCount());
  if (need > memory_limit)
    throw InputError(file, lines[0].number,
                     "a " + std::to_string(m.dims[0]) + "x" + std::to_string(m.dims[1]) + "x" + std::to_string(m.dims[2]) + " map needs " +
                         formatBytes(need) + " to grow in, more than the limit of " + formatBytes(memory_limit) +
                         "; use a coarser map or raise --memory-limit");
  m.demand.assign(static_cast<std::size_t>(m.voxelCount()), 0.0f);
  if ((lines.size() - 1) % 2 != 0)
    throw InputError(file, lines.back().number, "a box line has no value line after it; expected pairs of 'x0 y0 z0 x1 y1 z1' and 'value'");
  for (std::size_t i = 1; i + 1 < lines.size(); i += 2) {
    const Box b = readBox(lines[i], file, m.dims);
    const auto w = splitWords(lines[i + 1].text);
    if (w.size() != 1) throw InputError(file, lines[i + 1].number, "expected one demand value, got '" + lines[i + 1].text + "'");
    const double v = parseNumber(w[0], file, lines[i + 1].number, "demand");
    if (v < 0 || v > 1e30) throw InputError(file, lines[i + 1].number, "demand " + w[0] + " is out of range; allowed: 0 (obstacle) to 1e30");
    forBox(m, b, [&](std::int64_t x) { m.demand[x] = static_cast<float>(v); });
  }

  m.supply_index.assign(m.demand.size(), 0);
  if (sc.supply_map.empty()) {
    m.supply_sets = {sc.supply_coefficients};
  } else {
    const std::string sfile = sc.supply_map.string();
    const auto sl = readTextLines(sc.supply_map, "supply map");
    if (sl.empty()) throw InputError(sfile, 0, "empty supply map; expected 'DX DY DZ K' then box and coefficient lines");
    const auto w0 = splitWords(sl[0].text);
    const auto sdims = readDims(sl[0], sfile, 4, "supply map");
    if (sdims != m.dims)
      throw InputError(sfile, sl[0].number,
                       "supply map size differs from the demand map's " + std::to_string(m.dims[0]) + " " + std::to_string(m.dims[1]) + " " +
                           std::to_string(m.dims[2]));
    const auto K = parseInteger(w0[3], sfile, sl[0].number, "K");
    if (K < 1 || K > 16) throw InputError(sfile, sl[0].number, "K = " + w0[3] + " is out of range; allowed: 1 to 16 values per voxel");
    m.supply_sets = {{}};  // index 0: not covered by any box, no reduction
    if ((sl.size() - 1) % 2 != 0) throw InputError(sfile, sl.back().number, "a box line has no coefficient line after it");
    for (std::size_t i = 1; i + 1 < sl.size(); i += 2) {
      const Box b = readBox(sl[i], sfile, m.dims);
      const auto w = splitWords(sl[i + 1].text);
      if (static_cast<std::int64_t>(w.size()) != K)
        throw InputError(sfile, sl[i + 1].number, "expected K = " + std::to_string(K) + " coefficients, got '" + sl[i + 1].text + "'");
      std::vector<double> c;
      for (const auto& x : w) c.push_back(parseNumber(x, sfile, sl[i + 1].number, "supply coefficient"));
      if (c.back() < 0 || c.back() > Limits::kMaxSupplyCutoff)
        throw InputError(sfile, sl[i + 1].number, "the last coefficient is the cut-off radius (map voxels); allowed: 0 to 1e6");
      auto it = std::find(m.supply_sets.begin(), m.supply_sets.end(), c);
      if (it == m.supply_sets.end()) {
        if (m.supply_sets.size() >= 65535) throw InputError(sfile, sl[i + 1].number, "more than 65534 distinct coefficient sets");
        m.supply_sets.push_back(c);
        it = m.supply_sets.end() - 1;
      }
      const auto idx = static_cast<std::uint16_t>(it - m.supply_sets.begin());
      forBox(m, b, [&](std::int64_t x) { m.supply_index[x] = idx; });
    }
  }

  const Vec3 r = sc.root_voxel;
  const std::string size = std::to_string(m.dims[0]) + " x " + std::to_string(m.dims[1]) + " x " + std::to_string(m.dims[2]);
  if (r.x < 0 || r.y < 0 || r.z < 0 || r.x >= m.dims[0] || r.y >= m.dims[1] || r.z >= m.dims[2])
    throw InputError(
        sc.parameter_file, sc.root_line,
        "the root (" + show3(r) + " map voxels) lies outside the " + size + " demand map; allowed: 0 <= x < " + std::to_string(m.dims[0]) + " etc.");
  if (!m.perfusable(m.toMm(r)))
    throw InputError(sc.parameter_file, sc.root_line,
                     "the root (" + show3(r) + " map voxels) lies in a zero-demand voxel of " + file + "; place it where the demand is > 0");
  double total = 0;
  for (float d : m.demand) total += d;
  if (!(total > 0)) throw InputError(file, 0, "the demand map is zero everywhere; give some box a demand > 0");
  return m;
}

}  // namespace angiosynth
