// The benchmark's report (one HTML file that needs nothing else: inline CSS, SVG curves, PNG
// thumbnails as data URIs; no script, no font, no request) and its CSV.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>

#include "angiosynth/version.hpp"
#include "core/format.hpp"
#include "benchmark/benchmark.hpp"

namespace angiosynth {
namespace {

std::string escaped(const std::string& s) {
  std::string o;
  for (char c : s) switch (c) {
      case '&': o += "&amp;"; break;
      case '<': o += "&lt;"; break;
      case '>': o += "&gt;"; break;
      case '"': o += "&quot;"; break;
      default: o += c;
    }
  return o;
}

std::string fixed(double v, int digits = 3) {
  if (!std::isfinite(v)) return "–";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

std::string csvNumber(double v) { return std::isfinite(v) ? show(v, 6) : std::string(); }

std::string base64(const std::string& in) {
  static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  std::size_t i = 0;
  for (; i + 2 < in.size(); i += 3) {
    const unsigned v = (unsigned char)in[i] << 16 | (unsigned char)in[i + 1] << 8 | (unsigned char)in[i + 2];
    out += table[v >> 18], out += table[v >> 12 & 63], out += table[v >> 6 & 63], out += table[v & 63];
  }
  if (i + 1 == in.size()) {
    const unsigned v = (unsigned char)in[i] << 16;
    out += table[v >> 18], out += table[v >> 12 & 63], out += "==";
  } else if (i + 2 == in.size()) {
    const unsigned v = (unsigned char)in[i] << 16 | (unsigned char)in[i + 1] << 8;
    out += table[v >> 18], out += table[v >> 12 & 63], out += table[v >> 6 & 63], out += '=';
  }
  return out;
}

// Okabe & Ito's colours, told apart with any colour vision.
const char* colour(std::size_t k) {
  static const char* c[] = {"#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#000000", "#F0E442"};
  return c[k % 8];
}

struct Series {
  std::string name;
  const char* colour;
  bool baseline, dashed;
  std::vector<double> mean, sd;  // per rung (NaN: none)
};

// A line chart on [0, 1]: one polyline per series, a dot per rung, ± SD bars when given.
std::string chart(const std::string& title, const std::string& x_title, const std::vector<std::string>& rungs, const std::vector<Series>& series) {
  const int w = 380, h = 250, left = 46, right = 12, top = 26, bottom = 58;
  const int pw = w - left - right, ph = h - top - bottom;
  const auto x = [&](std::size_t k) { return left + (rungs.size() == 1 ? pw / 2.0 : pw * double(k) / double(rungs.size() - 1)); };
  const auto y = [&](double v) { return top + ph * (1 - std::clamp(v, 0.0, 1.0)); };
  std::ostringstream s;
  s << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << w << "\" height=\"" << h << "\" viewBox=\"0 0 " << w << ' ' << h
    << "\" role=\"img\" aria-label=\"" << escaped(title) << "\">";
  s << "<text x=\"" << left << "\" y=\"16\" class=\"ct\">" << escaped(title) << "</text>";
  for (int t = 0; t <= 4; ++t) {
    const double v = t / 4.0;
    s << "<line x1=\"" << left << "\" x2=\"" << left + pw << "\" y1=\"" << y(v) << "\" y2=\"" << y(v) << "\" class=\"grid\"/>";
    s << "<text x=\"" << left - 6 << "\" y=\"" << y(v) + 4 << "\" class=\"yl\">" << fixed(v, 2) << "</text>";
  }
  for (std::size_t k = 0; k < rungs.size(); ++k) {
    std::string label = rungs[k].size() > 14 ? rungs[k].substr(0, 13) + "…" : rungs[k];
    s << "<text x=\"" << x(k) << "\" y=\"" << top + ph + 16 << "\" class=\"xl\">" << escaped(label) << "</text>";
  }
  s << "<text x=\"" << left + pw / 2 << "\" y=\"" << h - 14 << "\" class=\"xt\">" << escaped(x_title) << "</text>";
  for (const auto& se : series) {
    std::string points;
    for (std::size_t k = 0; k < se.mean.size(); ++k) {
      if (!std::isfinite(se.mean[k])) continue;
      char buf[64];
      std::snprintf(buf, sizeof buf, "%.1f,%.1f ", x(k), y(se.mean[k]));
      points += buf;
      if (k < se.sd.size() && std::isfinite(se.sd[k]) && se.sd[k] > 0)
        s << "<line x1=\"" << x(k) << "\" x2=\"" << x(k) << "\" y1=\"" << y(se.mean[k] - se.sd[k]) << "\" y2=\"" << y(se.mean[k] + se.sd[k])
          << "\" stroke=\"" << se.colour << "\" stroke-opacity=\"0.5\"/>";
      s << "<circle cx=\"" << x(k) << "\" cy=\"" << y(se.mean[k]) << "\" r=\"3\" fill=\"" << se.colour << "\"><title>" << escaped(se.name) << ", "
        << escaped(rungs[k]) << ": " << fixed(se.mean[k]) << "</title></circle>";
    }
    s << "<polyline points=\"" << points << "\" fill=\"none\" stroke=\"" << se.colour << "\" stroke-width=\"" << (se.baseline ? 1.6 : 2.8) << "\""
      << (se.dashed ? " stroke-dasharray=\"5 3\"" : "") << "/>";
  }
  s << "</svg>";
  return s.str();
}

const char* kStyle = R"(
body{font:14px/1.45 system-ui,-apple-system,"Segoe UI",sans-serif;margin:24px auto;max-width:1220px;color:#1b1b1b;padding:0 16px}
h1{font-size:24px;margin:0 0 4px}h2{font-size:19px;margin:28px 0 6px;border-bottom:1px solid #cccccc}
.meta{color:#555555;font-size:13px}.meta code{font-size:12px}
table{border-collapse:collapse;margin:8px 0 16px;font-size:13px}th,td{padding:3px 8px;text-align:right;border-bottom:1px solid #e4e4e4}
th{background:#f4f4f4}td.l,th.l{text-align:left}
.charts{display:flex;flex-wrap:wrap;gap:8px}.ct{font-size:13px;font-weight:600}.yl{font-size:10px;text-anchor:end;fill:#444444}
.xl{font-size:10px;text-anchor:middle;fill:#444444}.xt{font-size:11px;text-anchor:middle;fill:#222222}.grid{stroke:#e2e2e2}
.legend span{display:inline-block;margin-right:14px}.legend i{display:inline-block;width:18px;height:4px;margin-right:5px;vertical-align:middle}
.thumbs{display:flex;flex-wrap:wrap;gap:10px}figure{margin:0;text-align:center;font-size:12px}
figure img{width:150px;height:150px;image-rendering:pixelated;border:1px solid #bbbbbb;background:#000000}
)";

// The kinds of the rows' per-kind recall, in order of appearance.
std::vector<std::string> kindsOf(const std::vector<BenchmarkRow>& rows, const std::string& ladder = {}) {
  std::vector<std::string> kinds;
  for (const auto& r : rows)
    if (ladder.empty() || r.ladder == ladder)
      for (const auto& [name, v] : r.class_recall)
        if (std::find(kinds.begin(), kinds.end(), name) == kinds.end()) kinds.push_back(name);
  return kinds;
}

double kindRecall(const BenchmarkRow& r, const std::string& kind) {
  for (const auto& [name, v] : r.class_recall)
    if (name == kind) return v;
  return NAN;
}

}  // namespace

std::string benchmarkCsv(const std::vector<BenchmarkRow>& rows) {
  std::ostringstream s;
  s << "ladder,rung,label,method,baseline,cases,dice,dice_sd,cldice,cldice_sd,thin_vessel_recall,hd95_mm,precision,recall,centreline_recall,"
       "b0_error,tuned_fraction";
  std::size_t bins = 0;
  for (const auto& r : rows) bins = std::max(bins, r.calibre_lower.size());
  const BenchmarkRow* widest = nullptr;
  for (const auto& r : rows)
    if (r.calibre_lower.size() == bins) widest = &r;
  for (std::size_t b = 0; b < bins; ++b) s << ",calibre_recall_r" << csvNumber(widest->calibre_lower[b]) << "_voxels";
  const auto kinds = kindsOf(rows);
  for (const auto& k : kinds) s << ",recall_" << k;
  s << "\n";
  for (const auto& r : rows) {
    s << csvField(r.ladder) << ',' << r.rung << ',' << csvField(r.label) << ',' << csvField(r.method) << ',' << (r.baseline ? 1 : 0) << ','
      << r.cases;
    for (double v : {r.dice, r.dice_sd, r.cldice, r.cldice_sd, r.thin_recall, r.hd95_mm, r.precision, r.recall, r.centreline_recall, r.b0_error,
                     r.tuned_fraction})
      s << ',' << csvNumber(v);
    for (std::size_t b = 0; b < bins; ++b) s << ',' << (b < r.calibre_recall.size() ? csvNumber(r.calibre_recall[b]) : "");
    for (const auto& k : kinds) s << ',' << csvNumber(kindRecall(r, k));
    s << "\n";
  }
  return s.str();
}

std::string benchmarkReportHtml(const BenchmarkSpec& spec, const BenchmarkSummary& summary, const std::vector<BenchmarkThumbnail>& thumbnails,
                                const std::string& command_line) {
  std::vector<std::string> methods, bases;  // a tuned baseline takes its method's colour, dashed
  std::map<std::string, bool> baseline, tuned;
  const std::string suffix = "-tuned";
  for (const auto& r : summary.rows) {
    if (std::find(methods.begin(), methods.end(), r.method) == methods.end()) methods.push_back(r.method);
    baseline[r.method] = r.baseline;
    tuned[r.method] = r.baseline && std::isfinite(r.tuned_fraction);
    const std::string base = tuned[r.method] ? r.method.substr(0, r.method.size() - suffix.size()) : r.method;
    if (std::find(bases.begin(), bases.end(), base) == bases.end()) bases.push_back(base);
  }
  const auto colourOf = [&](const std::string& method) {
    const std::string base = tuned[method] ? method.substr(0, method.size() - suffix.size()) : method;
    return colour(std::find(bases.begin(), bases.end(), base) - bases.begin());
  };
  std::ostringstream h;
  h << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>" << escaped(spec.title) << "</title><style>" << kStyle
    << "</style></head><body>\n";
  h << "<h1>" << escaped(spec.title) << "</h1>\n";
  if (!spec.description.empty()) h << "<p>" << escaped(spec.description) << "</p>\n";
  h << "<p class=\"meta\">angiosynth " << kVersion << " · dataset spec <code>" << escaped(spec.dataset.filename().string()) << "</code> · truth: "
    << (spec.truth == DatasetTruth::Exact ? "the exact mask (partial volume ≥ 0.5 or crossed by a centreline)" : "labelsTr (the training label)")
    << " · reference segmenters: ";
  for (std::size_t m = 0; m < spec.methods.size(); ++m) h << (m ? ", " : "") << escaped(spec.methods[m]);
  h << "<br>made by <code>" << escaped(command_line) << "</code></p>\n";
  h << "<p class=\"meta\">Each rung is the dataset with one value replaced; every number is the mean over the rung's cases (± the standard "
       "deviation as bars). Dice and clDice (Shit et al. 2021) against the truth; thin-vessel recall is the share of the exact centreline "
       "where the radius is below one voxel that the prediction covers; HD95 in mm; Betti-0 error = |components of prediction − of truth| "
       "(26-connected). Baselines: Otsu (1979) thresholding, and Frangi et al. (1998), Sato et al. (1998), Jerman et al. (2016) vesselness "
       "thresholded as <code>angiosynth segment</code> does.</p>\n";
  h << "<p class=\"legend\">";
  bool any_tuned = false;
  for (const auto& m : bases)
    h << "<span><i style=\"background:" << colourOf(m) << "\"></i>" << escaped(m) << (baseline[m] ? "" : " (yours)") << "</span>";
  for (const auto& m : methods) any_tuned |= tuned[m];
  if (any_tuned) h << "<span>dashed: the same method at its tuned threshold</span>";
  h << "</p>\n";
  if (any_tuned)
    h << "<p class=\"meta\">A tuned baseline (<code>&lt;method&gt;-tuned</code>, dashed) thresholds its response at the share of each case's "
         "response range (one share for the rung, shown in the table) that gives the best mean Dice against the truth: the most any global "
         "threshold rule could get from that filter, not a method one could deploy.</p>\n";
  for (const auto& l : spec.ladders) {
    h << "<h2 id=\"" << escaped(l.name) << "\">" << escaped(l.title) << "</h2>\n<p class=\"meta\">ladder <b>" << escaped(l.name) << "</b>: <code>"
      << escaped(l.key) << "</code> = ";
    for (std::size_t k = 0; k < l.values.size(); ++k) h << (k ? ", " : "") << escaped(l.values[k]);
    for (const auto& f : l.fixed) h << "; fixed <code>" << escaped(f.key) << " = " << escaped(f.value) << "</code>";
    h << "</p>\n<div class=\"charts\">";
    struct Plot {
      const char* title;
      double BenchmarkRow::*mean;
      double BenchmarkRow::*sd;
    };
    for (const Plot& p : {Plot{"Dice", &BenchmarkRow::dice, &BenchmarkRow::dice_sd}, Plot{"clDice", &BenchmarkRow::cldice, &BenchmarkRow::cldice_sd},
                          Plot{"thin-vessel recall (radius < 1 voxel)", &BenchmarkRow::thin_recall, nullptr}}) {
      std::vector<Series> series;
      for (std::size_t m = 0; m < methods.size(); ++m) {
        Series se{methods[m],
                  colourOf(methods[m]),
                  baseline[methods[m]],
                  tuned[methods[m]],
                  std::vector<double>(l.values.size(), NAN),
                  std::vector<double>(l.values.size(), NAN)};
        for (const auto& r : summary.rows)
          if (r.ladder == l.name && r.method == methods[m]) {
            const std::size_t k = std::stoul(r.rung);
            se.mean[k] = r.*p.mean;
            if (p.sd) se.sd[k] = r.*p.sd;
          }
        series.push_back(std::move(se));
      }
      h << chart(p.title, l.title, l.labels, series);
    }
    h << "</div>\n<div class=\"thumbs\">";
    for (const auto& t : thumbnails)
      if (t.ladder == l.name)
        h << "<figure><img alt=\"maximum projection of the first case of rung " << escaped(t.caption) << "\" src=\"data:image/png;base64,"
          << base64(t.png) << "\"><figcaption>" << escaped(t.caption) << "</figcaption></figure>";
    const auto kinds = kindsOf(summary.rows, l.name);
    h << "</div>\n<table><tr><th class=\"l\">rung</th><th class=\"l\">method</th><th>cases</th><th>Dice</th><th>clDice</th><th>thin recall</th>"
         "<th>HD95 mm</th><th>precision</th><th>recall</th>";
    for (const auto& k : kinds) h << "<th>recall " << escaped(k) << "</th>";
    h << "<th>Betti-0 error</th><th>s / case</th></tr>\n";
    const auto kindCells = [&](const BenchmarkRow& r) {
      std::string c;
      for (const auto& k : kinds) c += fixed(kindRecall(r, k)) + "</td><td>";
      return c;
    };
    for (const auto& r : summary.rows)
      if (r.ladder == l.name)
        h << "<tr><td class=\"l\">" << escaped(r.label) << "</td><td class=\"l\">" << escaped(r.method)
          << (std::isfinite(r.tuned_fraction) ? " (" + fixed(r.tuned_fraction, 4) + ")" : "") << "</td><td>" << r.cases << "</td><td>"
          << fixed(r.dice) << " ± " << fixed(r.dice_sd) << "</td><td>" << fixed(r.cldice) << " ± " << fixed(r.cldice_sd) << "</td><td>"
          << fixed(r.thin_recall) << "</td><td>" << fixed(r.hd95_mm, 2) << "</td><td>" << fixed(r.precision) << "</td><td>" << fixed(r.recall)
          << "</td><td>" << kindCells(r) << fixed(r.b0_error, 1) << "</td><td>" << (r.baseline ? fixed(r.seconds_per_case, 2) : "–")
          << "</td></tr>\n";
    h << "</table>\n";
  }
  h << "<p class=\"meta\">Numbers: results.csv and benchmark.json beside this file; each rung's cases, masks and full scores under "
       "<code>&lt;ladder&gt;/&lt;rung&gt;/</code>. Add your method with <code>--predictions NAME=DIR</code> "
       "(DIR/&lt;ladder&gt;/&lt;rung&gt;/&lt;case&gt;.nii.gz).</p>\n</body></html>\n";
  return h.str();
}

}  // namespace angiosynth
