#include "grow/cco/part_file.hpp"

#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/rng.hpp"
#include "files/atomic_file.hpp"

namespace angiosynth {
namespace {

constexpr char kMagic[8] = {'A', 'S', 'C', 'C', 'O', 'P', 'T', '1'};

template <class T>
void put(std::string& out, const T& v) {
  out.append(reinterpret_cast<const char*>(&v), sizeof(T));
}

// Reads from a byte string, refusing to run past its end.
struct Cursor {
  const std::string& bytes;
  std::size_t at = 0;
  const std::string& file;
  template <class T>
  T get() {
    if (bytes.size() - at < sizeof(T))
      throw InputError(file, 0, "ends early; allowed: a part file angiosynth wrote whole (remove it, then rerun the part's task)");
    T v;
    std::memcpy(&v, bytes.data() + at, sizeof(T));
    at += sizeof(T);
    return v;
  }
};

}  // namespace

std::filesystem::path ccoPartFile(const std::filesystem::path& dir, int part) {
  char name[32];
  std::snprintf(name, sizeof name, "part_%05d.ccopart", part);
  return dir / name;
}

void writeCcoPartFile(const std::filesystem::path& file, const CcoPart& part, const CcoPartKey& key) {
  const VascularTree& t = part.tree;
  const auto order = t.topDownOrder();  // parents first, so that the reader can add node after node
  std::vector<std::int32_t> index(std::size_t(t.nodeCount()), -1);
  for (std::size_t k = 0; k < order.size(); ++k) index[std::size_t(order[k])] = std::int32_t(k);
  std::string out(kMagic, sizeof kMagic);
  put(out, key.fingerprint);
  put(out, std::int32_t(key.part));
  put(out, std::int32_t(key.parts));
  put(out, std::int32_t(part.attempt));
  put(out, std::int32_t(part.report.repair_rounds));
  put(out, part.seconds);
  put(out, part.report.root_radius_mm);
  GrowthReport report = part.report;
  for (auto* c : report.counts()) put(out, *c);
  put(out, std::int64_t(order.size()));
  for (auto i : order) {
    for (int a = 0; a < 3; ++a) put(out, t.position[i][a]);
    put(out, std::int32_t(t.parent[i] < 0 ? -1 : index[std::size_t(t.parent[i])]));
    put(out, t.radius[i]);
  }
  put(out, hashName(out.data(), out.size()));
  writeFileAtomically(file, out);
}

std::optional<CcoPart> readCcoPartFile(const std::filesystem::path& file, const CcoPartKey& key) {
  std::ifstream in(file, std::ios::binary);
  if (!in) return std::nullopt;
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string name = file.string();
  if (bytes.size() < sizeof kMagic + 8 || std::memcmp(bytes.data(), kMagic, sizeof kMagic) != 0)
    throw InputError(name, 0,
                     "is not a part file; allowed: the part files `angiosynth generate --part` writes (move it away, or use another --parts-dir)");
  std::uint64_t sum;
  std::memcpy(&sum, bytes.data() + bytes.size() - 8, 8);
  if (sum != hashName(bytes.data(), bytes.size() - 8))
    throw InputError(name, 0,
                     "is damaged (its checksum differs); allowed: a part file as angiosynth wrote it (remove it, then rerun the part's task)");
  Cursor c{bytes, sizeof kMagic, name};
  const auto fingerprint = c.get<std::uint64_t>();
  const int part = c.get<std::int32_t>(), parts = c.get<std::int32_t>();
  if (fingerprint != key.fingerprint || part != key.part || parts != key.parts)
    throw InputError(name, 0,
                     "is part " + std::to_string(part) + " of " + std::to_string(parts) +
                         (fingerprint != key.fingerprint ? " grown from other parameters, seed or sample" : "") + "; allowed: part " +
                         std::to_string(key.part) + " of " + std::to_string(key.parts) +
                         " of this parameter file and seed (remove the old parts directory's files, or use another --parts-dir)");
  CcoPart p;
  p.attempt = c.get<std::int32_t>();
  p.report.repair_rounds = c.get<std::int32_t>();
  p.seconds = c.get<double>();
  p.report.root_radius_mm = c.get<double>();
  for (auto* v : p.report.counts()) *v = c.get<std::int64_t>();
  const auto nodes = c.get<std::int64_t>();
  constexpr std::size_t kNodeBytes = 3 * 8 + 4 + 8;
  if (nodes < 2 || std::uint64_t(nodes) > (bytes.size() - c.at) / kNodeBytes)
    throw InputError(name, 0,
                     "holds " + std::to_string(nodes) +
                         " nodes, more than its size allows or fewer than a vessel; allowed: remove it, then rerun the part's task");
  VascularTree& t = p.tree;
  t.reserve(std::size_t(nodes));
  for (std::int64_t i = 0; i < nodes; ++i) {
    const double px = c.get<double>(), py = c.get<double>(), pz = c.get<double>();
    const Vec3 x(px, py, pz);
    const auto parent = c.get<std::int32_t>();
    if ((i == 0) != (parent < 0) || parent >= i)
      throw InputError(name, 0,
                       "node " + std::to_string(i) + " has parent " + std::to_string(parent) +
                           ", not an earlier node; allowed: remove it, then rerun the part's task");
    t.addNode(x, parent);
    t.radius[std::size_t(i)] = c.get<double>();
  }
  return p;
}

}  // namespace angiosynth
