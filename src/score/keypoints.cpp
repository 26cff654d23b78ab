#include "score/keypoints.hpp"

#include <algorithm>
#include <fstream>
#include <sstream>
#include <tuple>

#include "core/error.hpp"
#include "files/text_lines.hpp"
#include "score/measures.hpp"

namespace angiosynth {

KeyPoints skeletonKeyPoints(const Volume<std::uint8_t>& s) {
  const auto& g = s.grid;
  const auto on = [&](std::int64_t i, std::int64_t j, std::int64_t k) { return g.contains(i, j, k) && s.at(i, j, k); };
  const auto degree = [&](std::int64_t i, std::int64_t j, std::int64_t k) {
    int n = 0;
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) n += (dx || dy || dz) && on(i + dx, j + dy, k + dz);
    return n;
  };
  KeyPoints out;
  Volume<std::uint8_t> junction(g);
  std::vector<std::array<std::int64_t, 3>> junctions, stack;
  for (std::int64_t k = 0; k < g.dims[2]; ++k)
    for (std::int64_t j = 0; j < g.dims[1]; ++j)
      for (std::int64_t i = 0; i < g.dims[0]; ++i) {
        if (!s.at(i, j, k)) continue;
        const int d = degree(i, j, k);
        if (d == 1) out.endpoints.push_back({g.centre(i, j, k), 0});
        if (d >= 3) junction.at(i, j, k) = 1, junctions.push_back({i, j, k});
      }
  // Each 26-connected cluster of junction voxels is one bifurcation, at its centroid.
  for (const auto& [i, j, k] : junctions) {
    if (!junction.at(i, j, k)) continue;
    Vec3 sum(0, 0, 0);
    int n = 0;
    junction.at(i, j, k) = 0;
    stack.push_back({i, j, k});
    while (!stack.empty()) {
      const auto [a, b, c] = stack.back();
      stack.pop_back();
      sum += g.centre(a, b, c);
      ++n;
      for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx)
            if (g.contains(a + dx, b + dy, c + dz) && junction.at(a + dx, b + dy, c + dz)) {
              junction.at(a + dx, b + dy, c + dz) = 0;
              stack.push_back({a + dx, b + dy, c + dz});
            }
    }
    out.bifurcations.push_back({sum / double(n), 0});
  }
  return out;
}

KeyPoints truthKeyPoints(const std::filesystem::path& file, const VolumeGrid& g) {
  std::ifstream in(file);
  if (!in) throw InputError(file.string(), 0, "cannot read the truth's key points");
  std::string line;
  std::getline(in, line);
  std::vector<std::string> header;
  {
    std::stringstream ss(line);
    for (std::string c; std::getline(ss, c, ',');) header.push_back(trimmed(c));
  }
  const auto column = [&](const char* name) {
    const auto it = std::find(header.begin(), header.end(), name);
    if (it == header.end()) throw InputError(file.string(), 1, std::string("no column '") + name + "' (angiosynth's keypoints.csv)");
    return std::size_t(it - header.begin());
  };
  const std::size_t type = column("type"), x = column("x_mm"), y = column("y_mm"), z = column("z_mm"), r = column("radius_mm");
  KeyPoints out;
  for (int number = 2; std::getline(in, line); ++number) {
    std::vector<std::string> cells;
    std::stringstream ss(line);
    for (std::string c; std::getline(ss, c, ',');) cells.push_back(c);
    if (cells.size() < header.size()) throw InputError(file.string(), number, "fewer cells than columns");
    const KeyPoint p{Vec3(parseNumber(cells[x], file.string(), number, "x_mm"), parseNumber(cells[y], file.string(), number, "y_mm"),
                          parseNumber(cells[z], file.string(), number, "z_mm")),
                     parseNumber(cells[r], file.string(), number, "radius_mm")};
    const Vec3 v = g.index(p.mm);
    if (!g.contains(std::llround(v.x), std::llround(v.y), std::llround(v.z))) continue;
    if (cells[type] == "bifurcation" || cells[type] == "junction")
      out.bifurcations.push_back(p);  // a junction: one branch point
    else if (cells[type] == "terminal" || cells[type] == "root")
      out.endpoints.push_back(p);
  }
  return out;
}

nlohmann::ordered_json matchKeyPoints(const std::vector<KeyPoint>& pred, const std::vector<KeyPoint>& truth, double min_tol) {
  // Candidate pairs within the truth point's tolerance, closest first (ties by index): greedy
  // one-to-one matching, the same on every run.
  std::vector<std::tuple<double, std::size_t, std::size_t>> pairs;
  for (std::size_t t = 0; t < truth.size(); ++t) {
    const double tol = std::max(min_tol, truth[t].radius);
    for (std::size_t p = 0; p < pred.size(); ++p) {
      const double d = distance(truth[t].mm, pred[p].mm);
      if (d <= tol) pairs.emplace_back(d, t, p);
    }
  }
  std::sort(pairs.begin(), pairs.end());
  std::vector<bool> t_used(truth.size()), p_used(pred.size());
  std::int64_t matched = 0;
  for (const auto& [d, t, p] : pairs)
    if (!t_used[t] && !p_used[p]) t_used[t] = p_used[p] = true, ++matched;
  nlohmann::ordered_json j{{"truth", truth.size()},
                           {"predicted", pred.size()},
                           {"matched", matched},
                           {"precision", ratio(double(matched), double(pred.size()))},
                           {"recall", ratio(double(matched), double(truth.size()))}};
  j["f1"] =
      pred.size() + truth.size() > 0 ? nlohmann::ordered_json(2.0 * matched / double(pred.size() + truth.size())) : nlohmann::ordered_json(nullptr);
  return j;
}

}  // namespace angiosynth
