// The report's "Recommendation" section (report_sections.hpp): per budget the verdict (the winner
// by mean FLIP, ties by time, and its margin) and the ranking; the methods whose memory the
// budget does not move; and the error-vs-bytes and error-vs-time Pareto fronts over every run.
#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "mfr/compare/report_ranking.hpp"
#include "mfr/core/units.hpp"
#include "report_common.hpp"
#include "report_sections.hpp"

namespace mfr::report {
namespace {

using RunKey = std::pair<size_t, size_t>;  // (budget, run)

// which runs are on a front, over every successful run of every budget
struct Fronts {
  std::map<RunKey, bool> bytes, time;
  bool onBytes(size_t b, size_t i) const { return find(bytes, b, i); }
  bool onTime(size_t b, size_t i) const { return find(time, b, i); }
  static bool find(const std::map<RunKey, bool>& m, size_t b, size_t i) {
    const auto it = m.find({b, i});
    return it != m.end() && it->second;
  }
};

Fronts frontsOf(const CompareResult& r) {
  std::vector<RunKey> keys;
  std::vector<FrontPoint> byBytes, byTime;
  for (size_t b = 0; b < r.budgets.size(); ++b)
    for (size_t i = 0; i < r.budgets[b].runs.size(); ++i) {
      const CompareRun& run = r.budgets[b].runs[i];
      if (!run.ok()) continue;
      keys.emplace_back(b, i);
      byBytes.push_back({run.metrics.flipMean, static_cast<double>(run.stats.bytesUsed)});
      byTime.push_back({run.metrics.flipMean, run.stats.totalMs()});
    }
  const std::vector<bool> onBytes = paretoFront(byBytes), onTime = paretoFront(byTime);
  Fronts f;
  for (size_t k = 0; k < keys.size(); ++k) {
    f.bytes[keys[k]] = onBytes[k];
    f.time[keys[k]] = onTime[k];
  }
  return f;
}

std::string flipText(double flip) {
  return flip == 0.0 ? std::string("0 (exact)") : format("%.4f", flip);
}

std::string msText(double ms) {
  return format("%.1f&#8201;ms", std::fabs(ms));
}

// one sentence: who wins this budget and by how much
std::string verdict(const CompareBudget& cb) {
  const Recommendation rec = recommend(cb);
  if (!rec.winner) return "no method fits this budget.";
  const CompareRun& w = cb.runs[*rec.winner];
  const std::string name = "<strong class=\"winner\">" + escape(w.label) + "</strong>";
  if (!rec.runnerUp)
    return name + " is the only method that fits (FLIP " + flipText(w.metrics.flipMean) + ").";
  const CompareRun& s = cb.runs[*rec.runnerUp];
  if (rec.flipMargin == 0.0)
    return name + " and " + escape(s.label) + " tie on FLIP (" + flipText(w.metrics.flipMean) +
           "); " + escape(w.label) +
           (rec.timeMarginMs > 0.0 ? " is faster by " + msText(rec.timeMarginMs)
                                   : " is as fast (" + msText(w.stats.totalMs()) + ")") +
           ".";
  std::string v = name + " wins with FLIP " + flipText(w.metrics.flipMean) + ", " +
                  format("%.4f", rec.flipMargin) + " below the runner-up " + escape(s.label) +
                  " (" + format("%.4f", s.metrics.flipMean) +
                  format("; %.0f&#8201;%% lower)", 100.0 * rec.relativeMargin);
  v += rec.timeMarginMs >= 0.0 ? ", and is faster by " + msText(rec.timeMarginMs)
                               : ", but slower by " + msText(rec.timeMarginMs);
  return v + ".";
}

// "kplus-dynamic wins at 2 of 3 budgets"
std::string overall(const CompareResult& r) {
  std::map<std::string, int> wins;
  for (const CompareBudget& cb : r.budgets)
    if (const Recommendation rec = recommend(cb); rec.winner) ++wins[cb.runs[*rec.winner].label];
  if (r.budgets.size() < 2 || wins.empty()) return {};
  std::vector<std::pair<int, std::string>> order;
  for (const auto& [method, n] : wins) order.emplace_back(-n, method);
  std::sort(order.begin(), order.end());
  std::string h = "<p class=\"verdict\">Overall: ";
  for (size_t i = 0; i < order.size(); ++i)
    h += (i ? "; " : "") + std::string(i ? "" : "<strong>") + escape(order[i].second) +
         (i ? "" : "</strong>") +
         format(" wins at %d of %zu budgets", -order[i].first, r.budgets.size());
  return h + ".</p>\n";
}

std::string tags(bool bytesFront, bool timeFront, bool fixed) {
  std::string t;
  if (bytesFront) t += "<span class=\"tag front\">bytes front</span>";
  if (timeFront) t += "<span class=\"tag front\">time front</span>";
  if (fixed) t += "<span class=\"tag fixed\">fixed memory</span>";
  return t;
}

const char* kRankingHeader =
    "<thead><tr><th>Rank</th><th>Method</th><th>FLIP<span class=\"unit\">mean</span></th>"
    "<th>&Delta; FLIP<span class=\"unit\">vs the winner</span></th>"
    "<th>MSE<span class=\"unit\">linear</span></th>"
    "<th>Time<span class=\"unit\">total, ms</span></th>"
    "<th>Memory used<span class=\"unit\">MiB</span></th>"
    "<th>Bytes per pixel<span class=\"unit\">bytes_used / pixels</span></th>"
    "<th>Notes</th></tr></thead><tbody>";

// one budget's runs, best first (failed runs last), sortable
std::string rankingTable(const CompareResult& r, size_t b, const Fronts& fronts,
                         const std::vector<std::string>& fixed) {
  const CompareBudget& cb = r.budgets[b];
  const std::vector<size_t> order = rankRuns(cb);
  const double pixels = static_cast<double>(r.width) * static_cast<double>(r.height);
  std::string t = "<table class=\"results ranking\" data-sortable>" + std::string(kRankingHeader);
  for (size_t k = 0; k < order.size(); ++k) {
    const CompareRun& run = cb.runs[order[k]];
    const double delta = run.metrics.flipMean - cb.runs[order[0]].metrics.flipMean;
    const bool isFixed = std::find(fixed.begin(), fixed.end(), run.label) != fixed.end();
    t += k == 0 ? "<tr class=\"winner\">" : "<tr>";
    t += numberCell(static_cast<double>(k + 1), std::to_string(k + 1));
    t += "<td><code>" + escape(run.label) + "</code></td>";
    t += numberCell(run.metrics.flipMean, format("%.4f", run.metrics.flipMean));
    t += numberCell(delta, k == 0 ? std::string("&mdash;") : format("+%.4f", delta));
    t += numberCell(run.metrics.mseLinear, sci(run.metrics.mseLinear));
    t += numberCell(run.stats.totalMs(), format("%.1f", run.stats.totalMs()));
    t += numberCell(static_cast<double>(run.stats.bytesUsed), mib(run.stats.bytesUsed));
    const double bpp = static_cast<double>(run.stats.bytesUsed) / pixels;
    t += numberCell(bpp, format("%.1f", bpp));
    t += "<td class=\"note\">" +
         tags(fronts.onBytes(b, order[k]), fronts.onTime(b, order[k]), isFixed) + "</td></tr>";
  }
  for (const CompareRun& run : cb.runs)
    if (!run.ok())
      t += "<tr class=\"failed\"><td>&ndash;</td><td><code>" + escape(run.label) +
           "</code></td><td class=\"err\" colspan=\"7\">failed: " + escape(*run.error) +
           "</td></tr>";
  return t + "</tbody></table>";
}

// the methods the budget does not move, with what they use and whether their error moves
std::string fixedNote(const CompareResult& r, const std::vector<std::string>& fixed) {
  if (fixed.empty()) return {};
  std::string h =
      "<div class=\"fixed-note\" id=\"fixed-memory\"><strong>Fixed memory.</strong> The budget "
      "does not move these methods: each used the same bytes at every budget where it ran, so "
      "their rows repeat from budget to budget. <ul>";
  for (const std::string& method : fixed) {
    const CompareRun* first = nullptr;
    bool sameError = true;
    for (const CompareBudget& cb : r.budgets)
      for (const CompareRun& run : cb.runs)
        if (run.label == method && run.ok()) {
          if (!first) first = &run;
          sameError = sameError && run.metrics.flipMean == first->metrics.flipMean;
        }
    h += "<li><code>" + escape(method) + "</code>: " + escape(formatBytes(first->stats.bytesUsed)) +
         " at every budget where it ran" +
         (sameError ? ", the same error (FLIP " + format("%.4f", first->metrics.flipMean) + ")"
                    : std::string(", its error still changes (e.g. timing or noise)")) +
         "</li>";
  }
  return h + "</ul></div>\n";
}

// every run as a point of (cost, mean FLIP), one series per method, front runs ringed and joined
std::string frontFigure(const CompareResult& r, bool byTime, const Fronts& fronts) {
  if (r.budgets.empty()) return {};
  const double pixels = static_cast<double>(r.width) * static_cast<double>(r.height);
  std::vector<Series> series;
  std::vector<std::pair<double, double>> front;
  std::vector<double> costs;
  for (size_t m = 0; m < r.budgets[0].runs.size(); ++m) {
    Series s;
    s.name = r.budgets[0].runs[m].label;
    s.colour = paletteColour(m);
    s.marker = static_cast<int>(m);
    s.line = !byTime;
    for (size_t b = 0; b < r.budgets.size(); ++b) {
      const CompareRun& run = r.budgets[b].runs[m];
      if (!run.ok()) continue;
      const double cost =
          byTime ? run.stats.totalMs() : static_cast<double>(run.stats.bytesUsed) / pixels;
      const bool on = byTime ? fronts.onTime(b, m) : fronts.onBytes(b, m);
      s.points.emplace_back(cost, run.metrics.flipMean);
      s.onFront.push_back(on);
      s.labels.push_back(s.name + " at " + r.budgets[b].label +
                         format(": FLIP %.4f, ", run.metrics.flipMean) +
                         (byTime ? format("%.1f ms", cost) : format("%.1f B/pixel", cost)) +
                         (on ? " (on the front)" : ""));
      if (on) front.emplace_back(cost, run.metrics.flipMean);
      costs.push_back(cost);
    }
    series.push_back(std::move(s));
  }
  if (costs.size() < 2) return {};
  std::sort(front.begin(), front.end());
  PlotSpec spec;
  spec.title = byTime ? "Mean FLIP vs time" : "Mean FLIP vs bytes per pixel";
  spec.xLabel = byTime ? "total time, ms" : "bytes per pixel charged (bytes_used / pixels)";
  spec.yLabel = "mean FLIP";
  spec.errorY = true;
  spec.front = front;
  const auto [lo, hi] = std::minmax_element(costs.begin(), costs.end());
  if (byTime)
    spec.logX = chooseAxisScale(costs).log;
  else
    setBytesPerPixelAxis(spec, *lo, *hi);
  return "<figure>" + svgPlot(spec, series) + "<figcaption>" +
         (byTime ? std::string("Every run's error against its total time. ")
                 : std::string("Every run's error against the memory it was charged per pixel: "
                               "methods that do not spend the whole budget sit where they "
                               "really are. ")) +
         "Ringed and joined by the dashed line: the Pareto front, the runs no other run beats "
         "on both error and " +
         (byTime ? "time" : "bytes") + ". Hover a point for its run.</figcaption></figure>\n";
}

}  // namespace

std::string recommendationSection(const CompareResult& r, int section) {
  const Fronts fronts = frontsOf(r);
  const std::vector<std::string> fixed = fixedMemoryMethods(r);
  std::string h = format("<h2 id=\"recommendation\">%d&ensp;Recommendation</h2>\n", section);
  h += "<p class=\"caption\">Per budget, the methods ranked by mean FLIP against the ground "
       "truth (lower is better), ties broken by total time; the winner and its margin over the "
       "runner-up.</p>\n<ul class=\"verdicts\">";
  for (const CompareBudget& cb : r.budgets)
    h += "<li><b>M = " + escape(cb.label) + "</b>: " + verdict(cb) + "</li>";
  h += "</ul>\n" + overall(r) + fixedNote(r, fixed);
  h += "<div class=\"plots\">\n" + frontFigure(r, false, fronts) + frontFigure(r, true, fronts) +
       "</div>\n";
  for (size_t b = 0; b < r.budgets.size(); ++b) {
    h += "<h3>Ranking at M = " + budgetTitle(r.budgets[b]) + "</h3>\n";
    h += rankingTable(r, b, fronts, fixed) + "\n";
  }
  return h;
}

}  // namespace mfr::report
