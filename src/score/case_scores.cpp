#include "score/case_scores.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <fstream>

#include "core/distance_transform.hpp"
#include "core/error.hpp"
#include "io/network_files.hpp"
#include "io/nifti_reader.hpp"
#include "settings/param_checks.hpp"
#include "score/betti.hpp"
#include "score/keypoints.hpp"
#include "score/skeleton.hpp"

namespace angiosynth {
namespace {

using Json = nlohmann::ordered_json;

Volume<std::uint8_t> binary(const Volume<float>& v) {
  Volume<std::uint8_t> out(v.grid);
  for (std::size_t i = 0; i < v.data.size(); ++i) out.data[i] = v.data[i] > 0;
  return out;
}

double smallestEdge(const VolumeGrid& g) { return std::min({g.spacing_mm.x, g.spacing_mm.y, g.spacing_mm.z}); }

}  // namespace

Json ratio(double num, double den) { return den > 0 ? Json(num / den) : Json(nullptr); }

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

Json surfaceScores(const Volume<std::uint8_t>& pred, const Volume<std::uint8_t>& truth, double tolerance_mm, bool topcow) {
  const Volume<std::uint8_t> bp = borderVoxels(pred, topcow), bt = borderVoxels(truth, topcow);
  const std::int64_t np = std::count(bp.data.begin(), bp.data.end(), 1), nt = std::count(bt.data.begin(), bt.data.end(), 1);
  Json j{{"border", topcow ? "foreground voxels with a background voxel among their 26 neighbours"
                           : "foreground voxels with a background voxel among their 6 face neighbours"},
         {"border_voxels_prediction", np},
         {"border_voxels_truth", nt},
         {"tolerance_mm", tolerance_mm}};
  if (np == 0 || nt == 0) {
    const Json none = np == nt ? Json(0.0) : (topcow ? Json(90.0) : Json(nullptr));
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
  const auto within = [&](const std::vector<double>& v) { return double(std::count_if(v.begin(), v.end(), [&](double x) { return x <= tolerance_mm; })); };
  j["hd_mm"] = std::max(max(p_to_t), max(t_to_p));
  j["hd95_mm"] = std::max(percentile95(p_to_t), percentile95(t_to_p));
  j["assd_mm"] = (sum(p_to_t) + sum(t_to_p)) / double(np + nt);
  j["masd_mm"] = 0.5 * (sum(p_to_t) / double(np) + sum(t_to_p) / double(nt));
  j["nsd"] = (within(p_to_t) + within(t_to_p)) / double(np + nt);
  return j;
}

Json clDice(const Volume<std::uint8_t>& pred_skeleton, const Volume<std::uint8_t>& truth, const Volume<std::uint8_t>& truth_skeleton,
           const Volume<std::uint8_t>& pred) {
  std::int64_t sp = 0, sp_in = 0, st = 0, st_in = 0;
  for (std::size_t i = 0; i < pred.data.size(); ++i) {
    if (pred_skeleton.data[i]) ++sp, sp_in += truth.data[i] != 0;
    if (truth_skeleton.data[i]) ++st, st_in += pred.data[i] != 0;
  }
  const Json tprec = ratio(double(sp_in), double(sp)), tsens = ratio(double(st_in), double(st));
  Json j{{"topology_precision", tprec}, {"topology_sensitivity", tsens}};
  if (tprec.is_null() || tsens.is_null()) j["cldice"] = nullptr;
  else {
    const double a = tprec.get<double>(), b = tsens.get<double>();
    j["cldice"] = a + b > 0 ? 2 * a * b / (a + b) : 0.0;
  }
  return j;
}

namespace {

// Geometry of the prediction against the truth: the same voxels in the same place.
void checkSameGrid(const NiftiVolume& pred, const NiftiVolume& truth, const std::string& pred_file, const std::string& truth_file) {
  const auto& a = pred.values.grid;
  const auto& b = truth.values.grid;
  const auto size = [](const VolumeGrid& g) {
    return std::to_string(g.dims[0]) + " x " + std::to_string(g.dims[1]) + " x " + std::to_string(g.dims[2]);
  };
  if (a.dims != b.dims)
    throw InputError(pred_file, 0, "the prediction has " + size(a) + " voxels, the truth (" + truth_file + ") " + size(b) +
                                       "; allowed: the truth's grid (resample the prediction onto it)");
  const double tol = 1e-3 * smallestEdge(b);
  for (std::size_t k = 0; k < 12; ++k)
    if (!(std::abs(pred.affine[k] - truth.affine[k]) <= tol)) {
      std::string pa, ta;
      for (std::size_t q = 0; q < 12; ++q) {  // appended piecewise: GCC 12 warns falsely (-Wrestrict) on " " + string
        if (q) pa += ' ', ta += ' ';
        pa += show(pred.affine[q]);
        ta += show(truth.affine[q]);
      }
      throw InputError(pred_file, 0, "the prediction's voxel-to-world affine [" + pa + "] is not the truth's [" + ta + "] (" + truth_file +
                                         "); allowed: the same to 1e-3 voxel (mm)");
    }
}

std::vector<double> binEdges(const std::vector<double>& lower) {
  std::vector<double> e = lower;
  e.push_back(INFINITY);
  return e;
}

Json binRange(double lo, double hi) { return Json::array({lo, std::isfinite(hi) ? Json(hi) : Json("inf")}); }

// Recall of the truth's exact centreline voxels, by calibre (radius in the unit `scale` of mm).
Json calibreRecall(const Volume<std::uint8_t>& pred, const Volume<std::uint8_t>& truth, const Volume<float>& centre,
                   const Volume<float>& radius, const std::vector<double>& lower, double scale, const char* unit) {
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
    bins.push_back(Json{{std::string("radius_") + unit, binRange(edges[b], edges[b + 1])},
                        {"centreline_voxels", n[b]},
                        {"recall", ratio(double(hit[b]), double(n[b]))},
                        {"truth_coverage", ratio(double(covered[b]), double(n[b]))}});
  return bins;
}

// Vessels of the generating graph (root or bifurcation to the next bifurcation or terminal,
// through continuation nodes), each sampled every quarter of the smallest voxel edge: detected
// when at least 80 % of its sampled length lies on predicted voxels; tree length detected; the
// same by bifurcation level (the bifurcations between a vessel and its tree's root).
Json vesselDetection(const Volume<std::uint8_t>& pred, const VascularTree& t) {
  const VolumeGrid& g = pred.grid;
  const double step = smallestEdge(g) / 4;
  // Level and vessel of each segment, top down (an N-ary junction's links merged into its node).
  std::vector<std::int32_t> level(t.nodeCount(), 0), vessel(t.nodeCount(), -1);
  std::vector<std::int32_t> vessel_level;
  for (auto i : t.topDownOrder()) {
    if (t.isRoot(i) || t.isLink(i)) continue;
    const auto p = t.junction(t.parent[i]);
    if (t.isRoot(p) || t.graphType(p) != NodeType::Continuation) {
      level[i] = t.isRoot(p) ? 0 : level[p] + 1;
      vessel[i] = std::int32_t(vessel_level.size());
      vessel_level.push_back(level[i]);
    } else {
      level[i] = level[p];
      vessel[i] = vessel[p];
    }
  }
  std::vector<double> length(vessel_level.size(), 0), found(vessel_level.size(), 0);
  for (std::int32_t s = 0; s < t.nodeCount(); ++s) {
    if (t.isRoot(s) || t.isLink(s)) continue;
    const Vec3 a = t.position[t.parent[s]], b = t.position[s];
    const double len = distance(a, b);
    const int n = std::max(1, int(std::ceil(len / step)));
    for (int q = 0; q < n; ++q) {
      const Vec3 x = g.index(a + (b - a) * ((q + 0.5) / n));
      const std::int64_t i = std::llround(x.x), j = std::llround(x.y), k = std::llround(x.z);
      if (!g.contains(i, j, k)) continue;
      length[vessel[s]] += len / n;
      found[vessel[s]] += pred.at(i, j, k) ? len / n : 0.0;
    }
  }
  const int levels = vessel_level.empty() ? 0 : *std::max_element(vessel_level.begin(), vessel_level.end()) + 1;
  std::vector<double> lvl_len(levels, 0), lvl_found(levels, 0);
  std::vector<std::int64_t> lvl_n(levels, 0), lvl_det(levels, 0);
  double total = 0, total_found = 0;
  std::int64_t counted = 0, detected = 0;
  for (std::size_t v = 0; v < vessel_level.size(); ++v) {
    if (!(length[v] > 0)) continue;  // outside the image
    const bool det = found[v] >= 0.8 * length[v];
    const int l = vessel_level[v];
    ++counted, detected += det, total += length[v], total_found += found[v];
    ++lvl_n[l], lvl_det[l] += det, lvl_len[l] += length[v], lvl_found[l] += found[v];
  }
  Json by_level = Json::array();
  for (int l = 0; l < levels; ++l)
    if (lvl_n[l] > 0)
      by_level.push_back(Json{{"level", l},
                              {"vessels", lvl_n[l]},
                              {"detected", lvl_det[l]},
                              {"detected_rate", ratio(double(lvl_det[l]), double(lvl_n[l]))},
                              {"length_mm", lvl_len[l]},
                              {"length_detected", ratio(lvl_found[l], lvl_len[l])}});
  return Json{{"vessels", counted},
              {"detected", detected},
              {"detected_rate", ratio(double(detected), double(counted))},
              {"tree_length_mm", total},
              {"tree_length_detected", ratio(total_found, total)},
              {"by_level", by_level}};
}

}  // namespace

std::map<int, std::string> classLegend(const nlohmann::ordered_json& sample) {
  std::map<int, std::string> legend;
  if (sample.contains("classes") && sample["classes"].is_object())
    for (const auto& [k, v] : sample["classes"].items()) {
      if (!v.is_string()) continue;
      try {
        const int value = std::stoi(k);
        if (value > 0 && value < 256) legend[value] = v.get<std::string>();
      } catch (const std::exception&) {
      }
    }
  return legend;
}

std::map<int, std::string> classLegend(const std::filesystem::path& sample_json) {
  std::ifstream in(sample_json);
  const Json j = Json::parse(in, nullptr, /*allow_exceptions=*/false);
  return j.is_discarded() ? std::map<int, std::string>{} : classLegend(j);
}

TruthFiles sampleTruth(const std::filesystem::path& dir) {
  if (!std::filesystem::is_directory(dir)) throw InputError(dir.string(), 0, "is not a directory; allowed: a sample directory angiosynth generate wrote");
  const auto need = [&](const char* name) {
    const auto f = dir / name;
    if (!std::filesystem::is_regular_file(f))
      throw InputError(dir.string(), 0, std::string("no ") + name + " in the sample directory; allowed: a directory angiosynth generate wrote (with volumes)");
    return f;
  };
  TruthFiles t;
  t.mask = need("mask.nii.gz"), t.centerline = need("centerline.nii.gz"), t.radius = need("radius.nii.gz");
  t.name = dir.string();
  if (std::filesystem::is_regular_file(dir / "edges.csv") && std::filesystem::is_regular_file(dir / "nodes.csv")) t.edges = dir / "edges.csv";
  if (std::filesystem::is_regular_file(dir / "keypoints.csv")) t.keypoints = dir / "keypoints.csv";
  if (std::filesystem::is_regular_file(dir / "classes.nii.gz") && std::filesystem::is_regular_file(dir / "sample.json")) {
    t.classes = dir / "classes.nii.gz";
    t.legend = classLegend(dir / "sample.json");
  }
  return t;
}

Json scoreCase(const std::filesystem::path& pred_file, const TruthFiles& files, const ScoreOptions& opt) {
  const auto &mask_file = files.mask, &centre_file = files.centerline, &radius_file = files.radius;
  // Per voxel while scoring: five volumes of floats and bytes, two distance maps, the borders.
  constexpr std::uint64_t kBytesPerVoxel = 4 * 4 + 2 * 8 + 4;
  const NiftiVolume truth = readNiftiVolume(mask_file, opt.memory_limit, kBytesPerVoxel, "the truth mask");
  const NiftiVolume pred = readNiftiVolume(pred_file, opt.memory_limit, kBytesPerVoxel, "the prediction");
  checkSameGrid(pred, truth, pred_file.string(), mask_file.string());
  const NiftiVolume centre = readNiftiVolume(centre_file, opt.memory_limit, kBytesPerVoxel, "the truth centreline");
  const NiftiVolume radius = readNiftiVolume(radius_file, opt.memory_limit, kBytesPerVoxel, "the truth radius");
  checkSameGrid(centre, truth, centre_file.string(), mask_file.string());
  checkSameGrid(radius, truth, radius_file.string(), mask_file.string());
  const Volume<std::uint8_t> p = binary(pred.values), t = binary(truth.values);
  const VolumeGrid& g = t.grid;
  const double voxel = smallestEdge(g);
  const double tau = opt.tolerance_mm > 0 ? opt.tolerance_mm : voxel;

  Json j;
  j["prediction"] = pred_file.string();
  j["truth"] = files.name;
  j["conventions"] = opt.topcow ? "TopCoW: 26-neighbour borders, 90 mm for a surface distance when one mask is empty, Dice and Jaccard 0 when both are"
                                : "default: 6-neighbour borders, null for a surface distance when one mask is empty, Dice and Jaccard 1 when both are";
  j["overlap"] = overlapScores(p, t, opt.topcow);
  j["surface"] = surfaceScores(p, t, tau, opt.topcow);
  // The exact centreline as the truth's skeleton: clDice's topology sensitivity.
  std::int64_t cl = 0, cl_hit = 0;
  for (std::size_t i = 0; i < centre.values.data.size(); ++i)
    if (centre.values.data[i] > 0) ++cl, cl_hit += p.data[i] != 0;
  j["centreline"] = Json{{"voxels", cl}, {"recall", ratio(double(cl_hit), double(cl))}};
  const Volume<std::uint8_t> pred_skeleton = skeletonize(p);
  {
    const Volume<std::uint8_t> st = skeletonize(t), sc = binary(centre.values);
    j["cldice"] = Json{{"skeletons", clDice(pred_skeleton, t, st, p)}, {"exact_centreline", clDice(pred_skeleton, t, sc, p)}};
  }
  if (!files.keypoints.empty()) {
    const KeyPoints found = skeletonKeyPoints(pred_skeleton), known = truthKeyPoints(files.keypoints, g);
    j["keypoints"] = Json{{"tolerance_mm", Json{{"at_least", 2 * voxel}, {"or", "the truth point's radius, if larger"}}},
                          {"bifurcations", matchKeyPoints(found.bifurcations, known.bifurcations, 2 * voxel)},
                          {"endpoints", matchKeyPoints(found.endpoints, known.endpoints, 2 * voxel)}};
  }
  {
    const Betti bp = bettiNumbers(p), bt = bettiNumbers(t);
    const auto json = [](const Betti& b) { return Json{{"b0", b.b0}, {"b1", b.b1}, {"b2", b.b2}, {"euler_characteristic", b.euler}}; };
    j["topology"] = Json{{"prediction", json(bp)},
                         {"truth", json(bt)},
                         {"b0_error", std::abs(bp.b0 - bt.b0)},
                         {"b1_error", std::abs(bp.b1 - bt.b1)},
                         {"b2_error", std::abs(bp.b2 - bt.b2)}};
  }
  j["calibre"] = calibreRecall(p, t, centre.values, radius.values, opt.bins_voxels, voxel, "voxels");
  if (!opt.bins_mm.empty()) j["calibre_mm"] = calibreRecall(p, t, centre.values, radius.values, opt.bins_mm, 1.0, "mm");
  if (!files.edges.empty()) j["vessels"] = vesselDetection(p, readNetwork(files.edges, 1, opt.memory_limit).tree);
  if (!files.classes.empty() && files.legend.size() >= 2) {
    const NiftiVolume cls = readNiftiVolume(files.classes, opt.memory_limit, kBytesPerVoxel, "the truth classes");
    checkSameGrid(cls, truth, files.classes.string(), mask_file.string());
    // A prediction labelled by kind (values above 1) is scored class by class; a binary one only
    // by what each class of the truth keeps (recall, centreline, calibre).
    const bool labelled = std::any_of(pred.values.data.begin(), pred.values.data.end(), [](float v) { return v > 1.5f; });
    Json per = Json::object();
    for (const auto& [value, name] : files.legend) {
      Volume<std::uint8_t> pk(g), tk(g);
      Volume<float> ck(g);
      for (std::size_t i = 0; i < pk.data.size(); ++i) {
        tk.data[i] = std::lround(cls.values.data[i]) == value;
        pk.data[i] = labelled ? std::lround(pred.values.data[i]) == value : p.data[i];
        ck.data[i] = tk.data[i] ? centre.values.data[i] : 0.0f;
      }
      Json c{{"label", value}};
      Json ov = overlapScores(pk, tk, opt.topcow);
      if (!labelled) ov = Json{{"recall", ov["recall"]}};
      c["overlap"] = ov;
      if (labelled) c["surface"] = surfaceScores(pk, tk, tau, opt.topcow);
      std::int64_t n = 0, hit = 0;
      for (std::size_t i = 0; i < ck.data.size(); ++i)
        if (ck.data[i] > 0) ++n, hit += pk.data[i] != 0;
      c["centreline"] = Json{{"voxels", n}, {"recall", ratio(double(hit), double(n))}};
      c["calibre"] = calibreRecall(pk, tk, ck, radius.values, opt.bins_voxels, voxel, "voxels");
      per[name] = c;
    }
    j["per_class"] = Json{{"prediction", labelled ? "labelled by kind (the truth's class values)" : "binary: recall-type scores only"},
                          {"classes", per}};
  }
  j["definitions"] = Json{
      {"prediction", "voxels > 0 are vessel"},
      {"truth", "the sample's mask.nii.gz (partial volume >= 0.5 or crossed by a centreline)"},
      {"overlap", "Dice 2TP/(2TP+FP+FN), Jaccard TP/(TP+FP+FN), precision TP/(TP+FP), recall TP/(TP+FN); null when the denominator is 0"},
      {"surface", "distances in mm between border voxel centres (spacing per axis); HD the largest directed distance; HD95 the larger of the "
                  "two directed 95th percentiles (linear interpolation, NumPy's default); ASSD the mean over both borders' distances; MASD "
                  "the mean of the two directed means; NSD the share of both borders within tolerance_mm of the other"},
      {"topology", "Betti numbers: b0 pieces of the foreground (26-connected), b2 cavities (6-connected background pieces not reaching the "
                   "outside; the volume padded with background), b1 tunnels = b0 + b2 - the Euler characteristic of the union of closed voxel "
                   "cubes; errors |prediction - truth|"},
      {"cldice", "clDice = 2 Tprec Tsens / (Tprec + Tsens), Tprec = share of the prediction's skeleton in the truth mask, Tsens = share "
                 "of the truth's skeleton in the prediction; skeletons by Lee's thinning in scikit-image's order (skeletonize_3d); "
                 "`exact_centreline` takes the exact centreline as the truth's skeleton; null when a skeleton is empty"},
      {"keypoints", "bifurcations and endpoints of the prediction's skeleton (26-neighbour count 1: an endpoint; each 26-connected "
                    "cluster of voxels with 3 or more: one bifurcation at its centroid) against the truth graph's bifurcations and "
                    "endpoints (terminals and roots, keypoints.csv), matched one to one closest first within max(2 voxels, the truth "
                    "point's radius); precision, recall, F1"},
      {"per_class", "with a truth of several kinds (classes.nii.gz, its legend in sample.json): each class's voxels against the "
                    "prediction's voxels of that value (a prediction labelled by kind), or, for a binary prediction, the share of each "
                    "class the prediction covers (recall, centreline recall, calibre)"},
      {"centreline", "share of the exact centreline's voxels (centerline.nii.gz) in the prediction: clDice's topology sensitivity with the exact skeleton"},
      {"calibre", "centreline voxels binned by the exact radius there (radius.nii.gz; in voxels of the smallest edge, or mm): recall = share in "
                  "the prediction, truth_coverage = share in the truth mask"},
      {"vessels", "vessels of the generating graph (root or bifurcation to the next bifurcation or terminal) sampled every quarter voxel at the "
                  "nearest voxel centre; detected when >= 80 % of the sampled length is predicted; level = bifurcations from the root"}};
  return j;
}

}  // namespace angiosynth
