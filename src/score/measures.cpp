#include "score/measures.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "core/distance_transform.hpp"
#include "core/error.hpp"
#include "core/quantity_json.hpp"
#include "settings/param_checks.hpp"

namespace angiosynth {

using Json = nlohmann::ordered_json;

Volume<std::uint8_t> binaryMask(const Volume<float>& v) {
  Volume<std::uint8_t> out(v.grid);
  for (std::size_t i = 0; i < v.data.size(); ++i) out.data[i] = v.data[i] > 0;
  return out;
}

double smallestEdge(const VolumeGrid& g) { return std::min({g.spacing_mm.x, g.spacing_mm.y, g.spacing_mm.z}); }

Json ratio(double num, double den) { return den > 0 ? Json(num / den) : Json(nullptr); }

nlohmann::ordered_json summaryOf(std::vector<double> v) {
  nlohmann::ordered_json s{{"cases", v.size()}};
  if (v.empty()) return s;
  std::sort(v.begin(), v.end());
  double sum = 0;
  for (double x : v) sum += x;
  const double mean = sum / double(v.size());
  double ss = 0;
  for (double x : v) ss += (x - mean) * (x - mean);
  const std::size_t n = v.size();
  s["mean"] = mean;
  s["median"] = n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
  s["sd"] = n > 1 ? nlohmann::ordered_json(std::sqrt(ss / double(n - 1))) : nlohmann::ordered_json(nullptr);
  s["min"] = v.front();
  s["max"] = v.back();
  return s;
}

Json overlapScores(const Volume<std::uint8_t>& pred, const Volume<std::uint8_t>& truth, bool topcow) {
  std::int64_t tp = 0, fp = 0, fn = 0;
  for (std::size_t i = 0; i < pred.data.size(); ++i) {
    const bool p = pred.data[i] != 0, t = truth.data[i] != 0;
    tp += p && t;
    fp += p && !t;
    fn += !p && t;
  }
  const bool both_empty = tp + fp + fn == 0;
  Json j{{"true_positive_voxels", tp}, {"false_positive_voxels", fp}, {"false_negative_voxels", fn}};
  j["dice"] = both_empty ? Json(topcow ? 0.0 : 1.0) : Json(2.0 * tp / double(2 * tp + fp + fn));
  j["jaccard"] = both_empty ? Json(topcow ? 0.0 : 1.0) : Json(double(tp) / double(tp + fp + fn));
  j["precision"] = ratio(double(tp), double(tp + fp));
  j["recall"] = ratio(double(tp), double(tp + fn));
  return j;
}

Volume<std::uint8_t> borderVoxels(const Volume<std::uint8_t>& v, bool all_neighbours) {
  const VolumeGrid& g = v.grid;
  Volume<std::uint8_t> out(g);
  const auto on = [&](std::int64_t i, std::int64_t j, std::int64_t k) { return g.contains(i, j, k) && v.at(i, j, k) != 0; };
  tbb::parallel_for(tbb::blocked_range<std::int32_t>(0, g.dims[2]), [&](const tbb::blocked_range<std::int32_t>& r) {
    for (std::int64_t k = r.begin(); k < r.end(); ++k)
      for (std::int64_t j = 0; j < g.dims[1]; ++j)
        for (std::int64_t i = 0; i < g.dims[0]; ++i) {
          if (!v.at(i, j, k)) continue;
          bool border = false;
          for (int dz = -1; dz <= 1 && !border; ++dz)
            for (int dy = -1; dy <= 1 && !border; ++dy)
              for (int dx = -1; dx <= 1 && !border; ++dx) {
                const int n = std::abs(dx) + std::abs(dy) + std::abs(dz);
                if (n == 0 || (!all_neighbours && n > 1)) continue;
                border = !on(i + dx, j + dy, k + dz);
              }
          out.at(i, j, k) = border;
        }
  });
  return out;
}

std::vector<double> directedBorderDistances(const Volume<std::uint8_t>& from, const Volume<std::uint8_t>& to) {
  const VolumeGrid& g = to.grid;
  std::vector<double> d2(to.data.size());
  for (std::size_t i = 0; i < d2.size(); ++i) d2[i] = to.data[i] ? 0.0 : kFarSquared;
  squaredDistances(d2, {g.dims[0], g.dims[1], g.dims[2]}, {g.spacing_mm.x, g.spacing_mm.y, g.spacing_mm.z});
  std::vector<double> out;
  for (std::size_t i = 0; i < from.data.size(); ++i)
    if (from.data[i]) out.push_back(std::sqrt(d2[i]));
  return out;
}

double percentile95(std::vector<double> v) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  const double x = 0.95 * double(v.size() - 1);
  const auto lo = static_cast<std::size_t>(std::floor(x));
  const std::size_t hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (x - double(lo)) * (v[hi] - v[lo]);
}

Json surfaceScores(const Volume<std::uint8_t>& pred, const Volume<std::uint8_t>& truth, double tolerance_mm, bool topcow, double missing_mm) {
  const Volume<std::uint8_t> bp = borderVoxels(pred, topcow), bt = borderVoxels(truth, topcow);
  const std::int64_t np = std::count(bp.data.begin(), bp.data.end(), 1), nt = std::count(bt.data.begin(), bt.data.end(), 1);
  Json j{{"border", topcow ? "foreground voxels with a background voxel among their 26 neighbours"
                           : "foreground voxels with a background voxel among their 6 face neighbours"},
         {"border_voxels_prediction", np},
         {"border_voxels_truth", nt},
         {"tolerance_mm", tolerance_mm}};
  if (np == 0 || nt == 0) {
    const Json none = np == nt ? Json(0.0) : (topcow ? Json(missing_mm) : Json(nullptr));
    for (const char* k : {"hd_mm", "hd95_mm", "assd_mm", "masd_mm"}) j[k] = none;
    j["nsd"] = np == nt ? Json(1.0) : Json(0.0);
    return j;
  }
  const std::vector<double> p_to_t = directedBorderDistances(bp, bt), t_to_p = directedBorderDistances(bt, bp);
  const auto max = [](const std::vector<double>& v) { return *std::max_element(v.begin(), v.end()); };
  const auto sum = [](const std::vector<double>& v) {
    double s = 0;
    for (double x : v) s += x;
    return s;
  };
  const auto within = [&](const std::vector<double>& v) {
    return double(std::count_if(v.begin(), v.end(), [&](double x) { return x <= tolerance_mm; }));
  };
  j["hd_mm"] = std::max(max(p_to_t), max(t_to_p));
  j["hd95_mm"] = std::max(percentile95(p_to_t), percentile95(t_to_p));
  j["assd_mm"] = (sum(p_to_t) + sum(t_to_p)) / double(np + nt);
  j["masd_mm"] = 0.5 * (sum(p_to_t) / double(np) + sum(t_to_p) / double(nt));
  j["nsd"] = (within(p_to_t) + within(t_to_p)) / double(np + nt);
  return j;
}

Json clDice(const Volume<std::uint8_t>& pred_skeleton, const Volume<std::uint8_t>& truth, const Volume<std::uint8_t>& truth_skeleton,
            const Volume<std::uint8_t>& pred, bool topcow) {
  std::int64_t sp = 0, sp_in = 0, st = 0, st_in = 0;
  for (std::size_t i = 0; i < pred.data.size(); ++i) {
    if (pred_skeleton.data[i]) ++sp, sp_in += truth.data[i] != 0;
    if (truth_skeleton.data[i]) ++st, st_in += pred.data[i] != 0;
  }
  // TopCoW scores an empty skeleton's share as 0, so that a case without vessels counts as a miss.
  const Json none = topcow ? Json(0.0) : Json(nullptr);
  const Json tprec = sp > 0 ? Json(double(sp_in) / double(sp)) : none, tsens = st > 0 ? Json(double(st_in) / double(st)) : none;
  Json j{{"topology_precision", tprec}, {"topology_sensitivity", tsens}};
  if (tprec.is_null() || tsens.is_null())
    j["cldice"] = nullptr;
  else {
    const double a = tprec.get<double>(), b = tsens.get<double>();
    j["cldice"] = a + b > 0 ? 2 * a * b / (a + b) : 0.0;
  }
  return j;
}

void checkSameGrid(const NiftiVolume& pred, const NiftiVolume& truth, const std::string& pred_file, const std::string& truth_file,
                   double tolerance_voxels) {
  const auto& a = pred.values.grid;
  const auto& b = truth.values.grid;
  const auto size = [](const VolumeGrid& g) {
    return std::to_string(g.dims[0]) + " x " + std::to_string(g.dims[1]) + " x " + std::to_string(g.dims[2]);
  };
  if (a.dims != b.dims)
    throw InputError(pred_file, 0,
                     "the prediction has " + size(a) + " voxels, the truth (" + truth_file + ") " + size(b) +
                         "; allowed: the truth's grid (resample the prediction onto it)");
  // The largest distance between a corner voxel's centres under the two affines, for the pair of
  // forms (sform, qform) of the two headers that agree best.
  const auto forms = [](const NiftiVolume& v) {
    std::vector<const std::array<double, 12>*> f{&v.affine};
    if (v.other_affine) f.push_back(&*v.other_affine);
    return f;
  };
  double best = INFINITY;
  const std::array<double, 12>*best_p = &pred.affine, *best_t = &truth.affine;
  for (const auto* p : forms(pred))
    for (const auto* t : forms(truth)) {
      double worst = 0;
      for (int corner = 0; corner < 8; ++corner) {
        const double idx[3] = {corner & 1 ? b.dims[0] - 1.0 : 0.0, corner & 2 ? b.dims[1] - 1.0 : 0.0, corner & 4 ? b.dims[2] - 1.0 : 0.0};
        double d2 = 0;
        for (int r = 0; r < 3; ++r) {
          double x = (*p)[std::size_t(r * 4 + 3)] - (*t)[std::size_t(r * 4 + 3)];
          for (int c = 0; c < 3; ++c) x += ((*p)[std::size_t(r * 4 + c)] - (*t)[std::size_t(r * 4 + c)]) * idx[c];
          d2 += x * x;
        }
        worst = std::max(worst, std::sqrt(d2));
      }
      if (worst < best) best = worst, best_p = p, best_t = t;
    }
  const double voxel = smallestEdge(b);
  if (best <= tolerance_voxels * voxel) return;
  std::string pa, ta;
  for (std::size_t q = 0; q < 12; ++q) {  // appended piecewise: GCC 12 warns falsely (-Wrestrict) on " " + string
    if (q) pa += ' ', ta += ' ';
    pa += show((*best_p)[q]);
    ta += show((*best_t)[q]);
  }
  throw InputError(pred_file, 0,
                   "the prediction's voxel-to-world affine [" + pa + "] is not the truth's [" + ta + "] (" + truth_file + "): a corner voxel lies " +
                       show(best, 4) + " mm (" + show(best / voxel, 4) + " voxels) away; allowed: within " + show(tolerance_voxels) +
                       " voxels (--grid-tolerance), sform or qform of either file");
}

namespace {

std::vector<double> binEdges(const std::vector<double>& lower) {
  std::vector<double> e = lower;
  e.push_back(INFINITY);
  return e;
}

}  // namespace

Json calibreRecall(const Volume<std::uint8_t>& pred, const Volume<std::uint8_t>& truth, const Volume<float>& centre, const Volume<float>& radius,
                   const std::vector<double>& lower, double scale, const char* unit) {
  const auto edges = binEdges(lower);
  std::vector<std::int64_t> n(lower.size()), hit(lower.size()), covered(lower.size());
  for (std::size_t i = 0; i < centre.data.size(); ++i) {
    if (!(centre.data[i] > 0)) continue;
    const double r = radius.data[i] / scale;
    for (std::size_t b = 0; b < lower.size(); ++b)
      if (r >= edges[b] && r < edges[b + 1]) {
        ++n[b];
        hit[b] += pred.data[i] != 0;
        covered[b] += truth.data[i] != 0;
      }
  }
  Json bins = Json::array();
  for (std::size_t b = 0; b < lower.size(); ++b)
    bins.push_back(Json{{std::string("radius_") + unit, rangeJson(edges[b], edges[b + 1])},
                        {"centreline_voxels", n[b]},
                        {"recall", ratio(double(hit[b]), double(n[b]))},
                        {"truth_coverage", ratio(double(covered[b]), double(n[b]))}});
  return bins;
}

}  // namespace angiosynth
