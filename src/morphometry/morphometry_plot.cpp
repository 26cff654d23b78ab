// The morphometry figure: a grid of histograms drawn on a plot canvas.
#include <cmath>

#include "core/forest.hpp"
#include "io/plot_canvas.hpp"
#include "morphometry/morphometry.hpp"

namespace angiosynth {
namespace {

constexpr int kPanelWidth = 330, kPanelHeight = 230, kColumns = 3, kBins = 24;

struct Panel {
  std::string title;
  std::vector<std::vector<double>> values;  // per kind
};

// One histogram: bins over the 1st to 99th percentile of all kinds' values, each kind's share
// per bin, scaled to the highest bar of any kind.
void histogram(PlotCanvas& c, int x0, int y0, const Panel& p, const std::vector<std::uint32_t>& colours) {
  std::vector<double> all;
  for (const auto& v : p.values)
    for (double x : v)
      if (std::isfinite(x)) all.push_back(x);
  const int left = x0 + 20, top = y0 + 30, width = kPanelWidth - 40, height = kPanelHeight - 80;
  c.text(p.title, x0 + kPanelWidth / 2, y0 + 6, true);
  c.line(left, top + height, left + width, top + height, 0x000000, 1);
  if (all.empty()) return;
  std::sort(all.begin(), all.end());
  double lo = all[std::size_t(0.01 * double(all.size() - 1))], hi = all[std::size_t(0.99 * double(all.size() - 1))];
  if (!(hi > lo)) lo -= 0.5, hi += 0.5;
  std::vector<std::vector<double>> share(p.values.size(), std::vector<double>(kBins, 0.0));
  double top_share = 0;
  for (std::size_t k = 0; k < p.values.size(); ++k) {
    double n = 0;
    for (double x : p.values[k])
      if (std::isfinite(x)) {
        // Clamped before the conversion: values beyond the percentiles may lie far outside.
        const double at = (x - lo) / (hi - lo) * kBins;
        const int b = at > 0 ? int(std::min(at, double(kBins - 1))) : 0;
        share[k][std::size_t(b)] += 1, n += 1;
      }
    for (auto& s : share[k]) top_share = std::max(top_share, s /= std::max(n, 1.0));
  }
  const auto bx = [&](int b) { return left + width * b / kBins; };
  const auto by = [&](double s) { return top + height - int(height * s / std::max(top_share, 1e-300)); };
  for (std::size_t k = 0; k < share.size(); ++k) {
    if (share.size() == 1) {
      for (int b = 0; b < kBins; ++b) c.box(bx(b) + 1, by(share[k][std::size_t(b)]), bx(b + 1) - 1, top + height, colours[k]);
      continue;
    }
    for (int b = 0; b < kBins; ++b) {  // a step line per kind
      const int y = by(share[k][std::size_t(b)]);
      c.line(bx(b), y, bx(b + 1), y, colours[k], 2);
      if (b + 1 < kBins) c.line(bx(b + 1), y, bx(b + 1), by(share[k][std::size_t(b + 1)]), colours[k], 2);
    }
  }
  const std::string l = plotLabel(std::round(lo * 1000) / 1000), h = plotLabel(std::round(hi * 1000) / 1000);
  c.text(l, left, top + height + 8);
  c.text(h, left + width - int(h.size()) * 12, top + height + 8);
}

}  // namespace

Image8 morphometryFigure(const Morphometry& m) {
  std::vector<std::string> kinds;
  for (const auto& k : m.tree_kinds)
    if (std::find(kinds.begin(), kinds.end(), k) == kinds.end()) kinds.push_back(k);
  if (kinds.empty()) kinds.push_back("tree");
  std::vector<std::uint32_t> colours;
  for (std::size_t k = 0; k < kinds.size(); ++k) colours.push_back(kinds.size() == 1 ? 0x4477AA : classColour(int(k) + 1));
  const auto kindIndex = [&](std::int32_t tree) {
    const std::string& k = std::size_t(tree) < m.tree_kinds.size() ? m.tree_kinds[std::size_t(tree)] : kinds.front();
    return std::size_t(std::find(kinds.begin(), kinds.end(), k) - kinds.begin());
  };
  std::vector<Panel> panels;
  const auto vesselPanel = [&](const std::string& title, double (*get)(const VesselMeasures&)) {
    Panel p{title, std::vector<std::vector<double>>(kinds.size())};
    for (const auto& v : m.vessels) p.values[kindIndex(v.tree)].push_back(get(v));
    panels.push_back(std::move(p));
  };
  const auto bifurcationPanel = [&](const std::string& title, double (*get)(const BifurcationMeasures&)) {
    Panel p{title, std::vector<std::vector<double>>(kinds.size())};
    for (const auto& b : m.bifurcations) p.values[kindIndex(b.tree)].push_back(get(b));
    panels.push_back(std::move(p));
  };
  vesselPanel("radius mm", [](const VesselMeasures& v) { return v.radius_mm; });
  vesselPanel("length mm", [](const VesselMeasures& v) { return v.length_mm; });
  vesselPanel("length / radius", [](const VesselMeasures& v) { return v.length_over_radius; });
  vesselPanel("distance metric", [](const VesselMeasures& v) { return v.distance_metric; });
  vesselPanel("generation", [](const VesselMeasures& v) { return double(v.generation); });
  vesselPanel("strahler order", [](const VesselMeasures& v) { return double(v.strahler); });
  bifurcationPanel("angle large daughter", [](const BifurcationMeasures& b) { return b.angle_large_deg; });
  bifurcationPanel("angle small daughter", [](const BifurcationMeasures& b) { return b.angle_small_deg; });
  bifurcationPanel("angle between daughters", [](const BifurcationMeasures& b) { return b.angle_between_deg; });
  bifurcationPanel("out of plane", [](const BifurcationMeasures& b) { return b.out_of_plane_deg; });
  bifurcationPanel("asymmetry", [](const BifurcationMeasures& b) { return b.asymmetry; });
  bifurcationPanel("murray exponent", [](const BifurcationMeasures& b) { return b.murray_exponent; });
  const int rows = (int(panels.size()) + kColumns - 1) / kColumns;
  PlotCanvas c(kColumns * kPanelWidth, rows * kPanelHeight + (kinds.size() > 1 ? 30 : 0));
  for (std::size_t k = 0; k < panels.size(); ++k) histogram(c, int(k % kColumns) * kPanelWidth, int(k / kColumns) * kPanelHeight, panels[k], colours);
  if (kinds.size() > 1)
    for (std::size_t k = 0; k < kinds.size(); ++k) {
      const int x = 20 + int(k) * 200, y = rows * kPanelHeight + 6;
      c.box(x, y, x + 14, y + 14, colours[k]);
      c.text(kinds[k], x + 24, y);
    }
  return c.img;
}

}  // namespace angiosynth
