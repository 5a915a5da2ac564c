// The report's "Images" section (report_sections.hpp): per budget a wiper (a method's image over
// the ground truth's, a slider between them), the grid of images and maps, and each run's worst
// region (the window of highest mean FLIP, from its FLIP map) beside the ground truth's, upscaled
// with nearest filtering. Crops and the wiper show the PNG files beside the page; nothing new is
// written.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "mfr/compare/report_ranking.hpp"
#include "report_common.hpp"
#include "report_sections.hpp"

namespace mfr::report {
namespace {

std::string imageGrid(const CompareResult& r, const CompareBudget& cb) {
  const CompareRun& gt = r.groundTruth;
  bool anyImportance = false;
  for (const CompareRun& run : cb.runs) anyImportance |= !run.importanceFile.empty();
  const size_t columns = 1 + cb.runs.size();
  std::string g = format(
      "<div class=\"scroll\"><div class=\"grid\" style=\"grid-template-columns: 22px "
      "repeat(%zu, minmax(150px, 1fr));\">",
      columns);
  // header
  g += "<div></div><div class=\"head\">ground truth<small>abuffer, exact</small></div>";
  for (const CompareRun& run : cb.runs) {
    g += "<div class=\"head\">" + escape(run.label);
    if (run.ok())
      g += "<small>" +
           format("FLIP %.4f &middot; PSNR %s dB", run.metrics.flipMean,
                  psnrText(run.metrics.psnrSrgb).c_str()) +
           "</small>";
    else
      g += "<small>failed</small>";
    g += "</div>";
  }
  // images
  g += "<div class=\"rowlabel\">image (sRGB)</div>";
  g += imageCell(gt.imageFile, gt.image, "ground truth (abuffer)", "");
  for (const CompareRun& run : cb.runs) {
    if (!run.ok()) {
      g += "<div class=\"cell failed\">" + escape(*run.error) + "</div>";
      continue;
    }
    g += imageCell(run.imageFile, run.image, run.label + " at " + cb.label, "");
  }
  // FLIP maps
  g += "<div class=\"rowlabel\">FLIP error</div>";
  g += "<div class=\"cell\"><div class=\"colorbar\" style=\"background: " + magmaGradient() +
       "\"></div><div class=\"colorbar-labels\"><span>0</span><span>FLIP error</span>"
       "<span>1</span></div></div>";
  for (const CompareRun& run : cb.runs)
    g += run.ok() ? imageCell(run.flipFile, run.flipMap, "FLIP error map of " + run.label,
                              format("mean %.4f", run.metrics.flipMean))
                  : std::string("<div class=\"cell empty\"></div>");
  // k-maps (the ground truth: its depth complexity, which is its k(p))
  g += "<div class=\"rowlabel\">k(p) / n(p)</div>";
  g += imageCell(r.depthComplexityFile, r.depthComplexityMap, "depth complexity n(p)",
                 gt.stats.maxDepthComplexity ? format("n(p), max %u", *gt.stats.maxDepthComplexity)
                                             : std::string("n(p)"));
  for (const CompareRun& run : cb.runs)
    g += run.ok() ? imageCell(run.kMapFile, run.kMap, "k(p) of " + run.label,
                              format("k %u&ndash;%u", run.stats.kMin, run.stats.kMax))
                  : std::string("<div class=\"cell empty\"></div>");
  if (anyImportance) {
    g += "<div class=\"rowlabel\">importance I(p)</div><div class=\"cell empty\"></div>";
    for (const CompareRun& run : cb.runs)
      g += run.ok() && !run.importanceFile.empty()
               ? imageCell(run.importanceFile, run.importanceMap, "importance map of " + run.label,
                           "I(p), Eqs. 3&ndash;6")
               : std::string("<div class=\"cell empty\"></div>");
  }
  g += "</div></div>";
  return g;
}

// the wiper's display width: a small image upscaled by a whole factor to about 512 px, a large
// one shown at most 768 px wide
int wiperWidth(int width) {
  if (width <= 0) return 0;
  const int w = width < 512 ? width * std::max(1, 512 / width) : width;
  return std::min(w, 768);
}

// the method's image (chosen in a list, the winner first) over the ground truth's, clipped at the
// slider's position: the method on the left, the ground truth on the right
std::string wiper(const CompareResult& r, const CompareBudget& cb) {
  const std::vector<size_t> order = rankRuns(cb);
  if (order.empty() || r.groundTruth.imageFile.empty()) return {};
  const CompareRun& first = cb.runs[order[0]];
  std::string h = format("<div class=\"wiper\" style=\"width: %dpx;\">", wiperWidth(r.width)) +
                  "<div class=\"controls\"><label>method <select "
                  "aria-label=\"method shown over the ground truth\">";
  for (size_t i : order)
    h += "<option value=\"" + escape(cb.runs[i].imageFile) + "\">" + escape(cb.runs[i].label) +
         "</option>";
  h += "</select></label><span class=\"caption\">Drag the slider: the method on the left, the "
       "ground truth on the right; methods best first.</span></div>";
  h += format("<div class=\"stage\" style=\"aspect-ratio: %d / %d;\">", r.width, r.height);
  h += "<img class=\"under\" src=\"" + escape(r.groundTruth.imageFile) + "\" alt=\"ground truth\">";
  h += "<img class=\"over\" src=\"" + escape(first.imageFile) + "\" alt=\"" + escape(first.label) +
       "\" style=\"clip-path: inset(0 50% 0 0);\">";
  h += "<div class=\"handle\" style=\"left: 50%;\"></div><span class=\"side left\">" +
       escape(first.label) + "</span><span class=\"side right\">ground truth</span></div>";
  return h +
         "<input type=\"range\" min=\"0\" max=\"100\" value=\"50\" step=\"0.5\" "
         "aria-label=\"wiper position\"></div>\n";
}

// `window` of the image in `file` (width x height), each pixel shown scale x scale
std::string cropView(const std::string& file, const CompareResult& r, const ImageWindow& window,
                     int scale, const std::string& label) {
  const int shown = window.size * scale;
  return format("<div class=\"crop\" style=\"width: %dpx; height: %dpx;\">", shown + 2, shown + 2) +
         "<img src=\"" + escape(file) + "\" alt=\"" + escape(label) + ", worst region\" " +
         format("style=\"width: %dpx; height: %dpx; left: %dpx; top: %dpx;\">", r.width * scale,
                r.height * scale, -window.x * scale, -window.y * scale) +
         "<span class=\"label\">" + escape(label) + "</span></div>";
}

// each run's worst window beside the same window of the ground truth and of its FLIP map
std::string worstRegions(const CompareResult& r, const CompareBudget& cb) {
  const int size = worstWindowSize(r.width, r.height);
  const int scale = std::max(1, static_cast<int>(std::lround(192.0 / std::max(1, size))));
  std::string h = "<div class=\"crops\">";
  for (size_t i : rankRuns(cb)) {
    const CompareRun& run = cb.runs[i];
    if (run.flipMap.rgba.empty()) continue;
    const ImageWindow w = worstWindow(flipValuesOfImage(run.flipMap), r.width, r.height, size);
    h += format("<figure class=\"cropset\" data-x=\"%d\" data-y=\"%d\" data-size=\"%d\">", w.x, w.y,
                w.size) +
         "<div class=\"title\">" + escape(run.label) + "</div>";
    if (w.mean <= 0.0) {
      h += "<figcaption>No error anywhere: the image is the ground truth's.</figcaption></figure>";
      continue;
    }
    h += "<div class=\"row\">" + cropView(r.groundTruth.imageFile, r, w, scale, "ground truth") +
         cropView(run.imageFile, r, w, scale, run.label) +
         cropView(run.flipFile, r, w, scale, "FLIP") + "</div>";
    h += format(
        "<figcaption>Pixels %d&ndash;%d &times; %d&ndash;%d (%d&times;%d, shown %d&times;): mean "
        "FLIP %.3f there, %.4f over the image.</figcaption></figure>",
        w.x, w.x + w.size - 1, w.y, w.y + w.size - 1, w.size, w.size, scale, w.mean,
        run.metrics.flipMean);
  }
  return h + "</div>\n";
}

}  // namespace

std::string imagesSection(const CompareResult& r, int section) {
  std::string h = format("<h2 id=\"images\">%d&ensp;Images</h2>\n", section);
  h += "<p class=\"caption\">Per budget: a wiper between a method's image and the ground truth; "
       "the grid of every run (columns: the ground truth, then each method; rows: the image "
       "(sRGB), the FLIP error map (magma, 0&ndash;1), " +
       format(
           "the slots per pixel k(p) (viridis, one scale 0&ndash;%g shared by all runs; the "
           "ground-truth column shows its depth complexity n(p), on its own scale)",
           static_cast<double>(r.kMapScale)) +
       ", and for the variable k-buffer its importance map I(p); click an image for full size); "
       "and each method's worst region, the window of highest mean FLIP in its FLIP map, beside "
       "the same window of the ground truth, upscaled without smoothing.</p>\n";
  for (const CompareBudget& cb : r.budgets) {
    h += "<h3>M = " + budgetTitle(cb) + "</h3>\n";
    h += wiper(r, cb) + imageGrid(r, cb) + "\n";
    h += "<h4>Worst regions</h4>\n" + worstRegions(r, cb);
  }
  return h;
}

}  // namespace mfr::report
