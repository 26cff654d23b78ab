#include "score/calibre_plot.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <map>

#include "core/error.hpp"
#include "io/plot_canvas.hpp"

namespace angiosynth {
namespace {

using Json = nlohmann::ordered_json;

}  // namespace

namespace {

// One case's bins, checked: an array of at most 64 objects, each with radius_voxels (an array
// whose first value is a finite, non-negative lower edge, increasing from bin to bin) and recall
// (a number in [0, 1], or null where the bin holds no voxel).
CalibreCurve checkedBins(const Json& bins, const std::string& file, const std::string& where) {
  const auto bad = [&](const std::string& why) -> InputError {
    return InputError(file, 0, where + why + "; allowed: the JSON angiosynth score writes");
  };
  if (!bins.is_array()) throw bad("\"calibre\" is not an array");
  if (bins.size() > 64) throw bad("\"calibre\" has " + std::to_string(bins.size()) + " bins, more than 64");
  CalibreCurve c;
  for (std::size_t b = 0; b < bins.size(); ++b) {
    const auto& bin = bins[b];
    const std::string at = "bin " + std::to_string(b);
    if (!bin.is_object()) throw bad(at + " is not an object");
    const auto edges = bin.find("radius_voxels");
    if (edges == bin.end() || !edges->is_array() || edges->empty() || !(*edges)[0].is_number())
      throw bad(at + " has no radius_voxels (an array of its lower and upper edge)");
    const double lower = (*edges)[0].get<double>();
    if (!std::isfinite(lower) || lower < 0 || (!c.lower.empty() && !(lower > c.lower.back())))
      throw bad(at + "'s lower edge " + std::to_string(lower) + " is not finite, non-negative and above the last bin's");
    const auto recall = bin.find("recall");
    if (recall == bin.end() || !(recall->is_null() || recall->is_number())) throw bad(at + " has no recall (a number, or null)");
    const double r = recall->is_number() ? recall->get<double>() : NAN;
    if (recall->is_number() && !(r >= 0 && r <= 1)) throw bad(at + "'s recall " + std::to_string(r) + " is not in [0, 1]");
    double upper = INFINITY;  // "inf", null or absent: the open last bin
    if (edges->size() > 1 && (*edges)[1].is_number()) upper = (*edges)[1].get<double>();
    if (!(upper > lower)) throw bad(at + "'s upper edge is not above its lower edge");
    c.lower.push_back(lower);
    c.upper.push_back(upper);
    c.recall.push_back(r);
  }
  return c;
}

}  // namespace

CalibreCurve calibreCurve(const Json& scores, const std::string& file) {
  if (!scores.is_object()) throw InputError(file, 0, "is not a score result (a JSON object of angiosynth score)");
  if (scores.contains("calibre")) return checkedBins(scores["calibre"], file, "");
  // A dataset: the mean per bin over the cases where the bin holds voxels.
  CalibreCurve c;
  if (!scores.contains("per_case")) return c;
  const auto& cases = scores["per_case"];
  if (!cases.is_array()) throw InputError(file, 0, "\"per_case\" is not an array; allowed: the JSON angiosynth score writes");
  std::vector<double> sum;
  std::vector<int> n;
  for (std::size_t k = 0; k < cases.size(); ++k) {
    const std::string where = "case " + std::to_string(k) + ": ";
    if (!cases[k].is_object() || !cases[k].contains("calibre"))
      throw InputError(file, 0, where + "has no \"calibre\"; allowed: the JSON angiosynth score writes");
    const CalibreCurve one = checkedBins(cases[k]["calibre"], file, where);
    if (k == 0) {
      c.lower = one.lower;
      c.upper = one.upper;
      sum.assign(one.lower.size(), 0);
      n.assign(one.lower.size(), 0);
    } else if (one.lower != c.lower) {
      throw InputError(file, 0, where + "has other calibre bins than case 0; allowed: one set of bins per dataset");
    }
    for (std::size_t b = 0; b < one.recall.size(); ++b)
      if (!std::isnan(one.recall[b])) sum[b] += one.recall[b], ++n[b];
  }
  for (std::size_t b = 0; b < c.lower.size(); ++b) c.recall.push_back(n[b] ? sum[b] / n[b] : NAN);
  return c;
}

namespace {

constexpr std::uint32_t kColours[] = {0xD62728, 0x1F77B4, 0x2CA02C, 0xFF7F0E, 0x9467BD, 0x8C564B, 0x17BECF, 0x7F7F7F};
constexpr std::size_t kLongestName = 32;  // characters of a legend entry

std::string legendName(const CalibreCurve& c, std::size_t k) {
  std::string n = c.name.empty() ? "curve " + std::to_string(k + 1) : c.name;
  return n.size() > kLongestName ? n.substr(0, kLongestName - 2) + ".." : n;
}

}  // namespace

int CalibrePlotFrame::x(double r) const { return left + int(std::sqrt(std::max(r, 0.0) / x_max) * plot_width); }
int CalibrePlotFrame::y(double recall) const { return top + int((1 - recall) * plot_height); }
double CalibrePlotFrame::binEnd(const CalibreCurve& c, std::size_t b) const {
  const double end = b < c.upper.size() ? c.upper[b] : b + 1 < c.lower.size() ? c.lower[b + 1] : INFINITY;
  if (std::isfinite(end)) return end;
  return c.lower[b] > 0 ? 2 * c.lower[b] : 1;
}

CalibrePlotFrame calibrePlotFrame(const std::vector<CalibreCurve>& curves) {
  CalibrePlotFrame f;
  std::size_t longest = 0;
  for (std::size_t k = 0; k < curves.size(); ++k) longest = std::max(longest, legendName(curves[k], k).size());
  f.left = 100, f.top = 30, f.plot_width = 560, f.plot_height = 330;
  f.width = f.left + f.plot_width + 40 + 24 + 12 * int(longest) + 20;
  f.height = f.top + f.plot_height + 80;
  f.x_max = 1;
  for (const auto& c : curves)
    if (!c.lower.empty()) f.x_max = std::max(f.x_max, f.binEnd(c, c.lower.size() - 1));
  return f;
}

Image8 plotCalibreCurves(const std::vector<CalibreCurve>& curves) {
  const CalibrePlotFrame f = calibrePlotFrame(curves);
  PlotCanvas c(f.width, f.height);
  const int left = f.left, top = f.top, pw = f.plot_width, ph = f.plot_height;
  for (int k = 0; k <= 4; ++k) c.line(left, f.y(k / 4.0), left + pw, f.y(k / 4.0), 0xE0E0E0, 1);  // grid
  c.line(left, top, left, top + ph, 0x000000, 2);
  c.line(left, top + ph, left + pw, top + ph, 0x000000, 2);
  for (double r : {0.0, 0.5, 1.0}) c.text(plotLabel(r), left - 10 - int(plotLabel(r).size()) * 12, f.y(r) - 7);  // right-aligned
  if (!curves.empty()) {
    const CalibreCurve& first = curves.front();
    for (std::size_t b = 0; b < first.lower.size(); ++b) {  // each bin's edges, where they are
      const int x = f.x(first.lower[b]);
      c.line(x, top + ph, x, top + ph + 6, 0x000000, 2);
      c.text(plotLabel(first.lower[b]), x - int(plotLabel(first.lower[b]).size()) * 6, top + ph + 12);
    }
    if (!first.upper.empty() && std::isinf(first.upper.back()))  // the open bin: "4+" at its middle
      c.text(plotLabel(first.lower.back()) + "+", (f.x(first.lower.back()) + left + pw) / 2 - 6, top + ph + 30);
  }
  c.text("radius in voxels (square-root axis)", left + pw / 2, f.height - 30, true);
  c.text("recall", 8, top + ph / 2, true, true);
  for (std::size_t k = 0; k < curves.size(); ++k) {
    const auto colour = kColours[k % 8];
    const auto& cv = curves[k];
    int last_x = -1, last_y = -1;
    for (std::size_t b = 0; b < cv.recall.size(); ++b) {
      if (!std::isfinite(cv.recall[b])) {
        last_x = -1;
        continue;
      }
      const int x0 = f.x(cv.lower[b]), x1 = f.x(f.binEnd(cv, b)), y = f.y(std::clamp(cv.recall[b], 0.0, 1.0));
      if (last_x >= 0) c.line(last_x, last_y, x0, y, colour, 1);  // the step between neighbouring bins
      c.line(x0, y, x1, y, colour, 3);                            // the bin's extent
      const int xm = f.x(0.5 * (cv.lower[b] + f.binEnd(cv, b)));
      c.box(xm - 4, y - 4, xm + 4, y + 4, colour);
      last_x = x1, last_y = y;
    }
    // Legend: the curve's name beside its colour.
    const int lx = left + pw + 40, ly = top + 10 + int(k) * 24;
    c.box(lx, ly, lx + 14, ly + 14, colour);
    c.text(legendName(cv, k), lx + 24, ly);
  }
  return c.img;
}

}  // namespace angiosynth
