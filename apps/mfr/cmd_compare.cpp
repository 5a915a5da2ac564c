// mfr compare: the ground truth and several methods at several budgets, written as images,
// results.json, results.csv and a self-contained report.html (the work is in the library:
// mfr/compare/compare.hpp).
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <utility>

#include "commands.hpp"
#include "common.hpp"
#include "mfr/compare/compare.hpp"
#include "mfr/compare/compare_output.hpp"
#include "mfr/compare/compare_request.hpp"
#include "mfr/compare/temporal.hpp"
#include "mfr/compare/temporal_run.hpp"
#include "mfr/core/atomic_file.hpp"
#include "mfr/core/image.hpp"
#include "mfr/core/quote.hpp"
#include "mfr/core/units.hpp"
#include "mfr/engine/render_views.hpp"

namespace mfr::cli {
namespace {

namespace fs = std::filesystem;

struct CompareArgs {
  SceneOptions scene;
  std::string budgets = "auto";
  std::string methods = kDefaultCompareMethods;
  std::string model;
  std::string out;
  std::string composite;            // empty: both rules for the methods that take both
  std::optional<int64_t> maxPeels;  // --max-peels (peel, dual-peel)
  std::string capture = "tile";
  double pixelsPerDegree = kFlipDefaultPixelsPerDegree;
  double orbitStep = 0.0;    // --orbit N without --orbit-view: degrees between frames (0: 360 / N)
  std::string sampleCounts;  // --sample-counts 1,4,8: the comparison at each count too
  int64_t repeat = 3;        // timed renders per run
  int64_t warmup = 1;        // untimed renders before them
  std::string truthEngine;   // empty: the engine's own, the CPU engine where a GPU refuses it
};

// The command line as typed (from /proc/self/cmdline), shell-quoted where needed.
std::string commandLine() {
  std::ifstream f("/proc/self/cmdline", std::ios::binary);
  std::string raw((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  std::string line;
  size_t start = 0;
  while (start < raw.size()) {
    size_t end = raw.find('\0', start);
    if (end == std::string::npos) end = raw.size();
    const std::string arg = raw.substr(start, end - start);
    start = end + 1;
    if (!line.empty()) line += ' ';
    const bool plain = !arg.empty() && arg.find_first_not_of(
                                           "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
                                           "0123456789-_./:,=+@%") == std::string::npos;
    if (plain) {
      line += arg;
    } else {
      line += '\'';
      for (char c : arg) {
        if (c == '\'')
          line += "'\\''";
        else
          line += c;
      }
      line += '\'';
    }
  }
  return line.empty() ? std::string("mfr compare") : line;
}

/// What results.json and the report record of this run: the version number ("mfr 1.2" -> "1.2")
/// and the report's version, command line and time.
std::pair<std::string, ReportInfo> provenance(const std::string& version) {
  std::string number = version;
  if (number.rfind("mfr ", 0) == 0) number.erase(0, 4);
  ReportInfo info;
  info.mfrVersion = version.empty() ? "mfr" : version;
  info.commandLine = commandLine();
  info.generated = utcTimestamp();
  return {number, info};
}

std::string psnrCell(double psnr) {
  if (!std::isfinite(psnr)) return "inf";
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.2f", psnr);
  return buffer;
}

// the rule column: kbuffer or hybrid; "own" for the methods with a rule of their own (wboit, ...)
const char* ruleName(const CompareRun& run) {
  return kBufferFamilyRule(run.compositing) ? toString(run.compositing) : "own";
}

void printSummary(const CompareResult& r) {
  std::fprintf(stderr, "%s %dx%d, ground truth (%s engine): %llu fragments, %s, %.1f ms\n",
               echoPath(r.scene).c_str(), r.width, r.height, r.truthEngine.c_str(),
               static_cast<unsigned long long>(r.groundTruth.stats.fragmentsGenerated),
               formatBytes(r.groundTruth.stats.bytesUsed).c_str(), r.groundTruth.stats.totalMs());
  if (r.autoBudgets) {
    std::string list;
    for (const CompareBudget& cb : r.budgets) list += (list.empty() ? "" : ", ") + cb.label;
    std::fprintf(stderr, "budgets from the scene (--budget auto): %s\n", list.c_str());
  }
  // ms: the median of the timed renders (--repeat), min-max beside it
  std::fprintf(stderr, "  %-22s %-7s %8s %11s %9s %7s %10s %9s %10s %8s %9s %s\n", "method", "rule",
               "budget", "used", "k", "lost%", "mse_lin", "psnr_lin", "psnr_srgb", "flip", "ms",
               "ms_range");
  for (const CompareBudget& cb : r.budgets)
    for (const CompareRun& run : cb.runs) {
      if (!run.ok()) {
        std::fprintf(stderr, "  %-22s %-7s %8s  failed: %s\n", run.label.c_str(), ruleName(run),
                     cb.label.c_str(), run.error->c_str());
        continue;
      }
      const RenderStats& s = run.stats;
      char k[32], range[48];
      std::snprintf(k, sizeof k, "%u-%u", s.kMin, s.kMax);
      std::snprintf(range, sizeof range, "%.1f-%.1f", run.timing.minMs, run.timing.maxMs);
      std::fprintf(stderr, "  %-22s %-7s %8s %11s %9s %7.2f %10.3e %9s %10s %8.4f %9.1f %s\n",
                   run.label.c_str(), ruleName(run), cb.label.c_str(),
                   formatBytes(s.bytesUsed).c_str(), k, s.lostPercent(), run.metrics.mseLinear,
                   psnrCell(run.metrics.psnrLinear).c_str(), psnrCell(run.metrics.psnrSrgb).c_str(),
                   run.metrics.flipMean, s.totalMs(), range);
    }
}

// --orbit N (no --orbit-view): every frame's comparison in DIR/frame_NNN, and the temporal
// stability of each method along the path (mfr/compare/temporal.hpp) in DIR/results.json,
// DIR/results.csv and DIR/report.html (its plots inline).
int runTemporal(const CompareArgs& a, CompareOptions options, const std::string& version,
                Engine& engine, const PreparedScene& prepared, Progress& progress,
                OutputFolder& outFolder) {
  const auto [versionNumber, info] = provenance(version);
  TemporalRequest request;
  request.scene = &prepared.scene;
  request.source = a.scene.source;
  request.start = prepared.cameras.front();
  request.frames = a.scene.orbit;
  request.stepDegrees = static_cast<float>(a.orbitStep);
  request.width = a.scene.width;
  request.height = a.scene.height;
  request.samples = a.scene.sampleCount();
  request.versionNumber = versionNumber;
  request.info = info;
  request.progress = [&progress](const std::string& stage, int done, int total) {
    progress.set(stage, done, total);
  };
  auto run = runTemporalComparison(engine, request, std::move(options), outFolder.staging());
  if (!run) return fail(run.error().message);
  if (auto placed = outFolder.commit(); !placed) return fail(placed.error().message);
  const TemporalResult& t = run->result;
  const int frames = request.frames;
  const float step = run->stepDegrees;
  const std::string& jsonText = run->jsonText;
  progress.clear();
  if (!a.scene.quiet) {
    std::fprintf(stderr, "%s, %d frames %.3g degrees apart; ground truth flicker %.4f\n",
                 echoPath(a.scene.source).c_str(), frames, step, t.groundTruthFlicker);
    // flip: the mean over the frames of each frame's mean FLIP against its ground truth (NaN
    // where a frame failed)
    std::fprintf(stderr, "  %-22s %8s %8s %9s %9s %12s\n", "method", "budget", "flip", "flicker",
                 "excess", "error change");
    for (const TemporalSeries& s : t.series)
      std::fprintf(stderr, "  %-22s %8s %8.4f %9.4f %9.4f %12.4f\n", s.method.c_str(),
                   s.budgetLabel.c_str(), s.meanFlip, s.flicker, s.excessFlicker,
                   s.meanErrorChange);
    std::fprintf(stderr, "report: %s\n",
                 echoPath((fs::path(a.out) / "report.html").string()).c_str());
  }
  if (a.scene.json) std::fputs(jsonText.c_str(), stdout);
  return 0;
}

int run(const CompareArgs& a, const std::string& version) {
  const bool temporal = a.scene.orbit != 0 && a.scene.orbitView < 0;
  if (temporal && a.scene.orbit < 2)
    return fail("--orbit " + std::to_string(a.scene.orbit) +
                ": a temporal comparison needs at least 2 frames (or add --orbit-view I)");
  if (!(a.orbitStep >= 0.0 && a.orbitStep <= 360.0))
    return fail("--orbit-step: must be in (0, 360] degrees");
  if (a.orbitStep > 0.0 && !temporal)
    return fail("--orbit-step: needs --orbit N (and no --orbit-view)");
  if (a.out.empty()) return fail("--out: an output folder is required");
  std::vector<int> sampleCounts;
  if (!a.sampleCounts.empty()) {
    if (temporal) return fail("--sample-counts: not with a temporal comparison (--orbit N)");
    auto counts = parseSampleCounts(a.sampleCounts, "--sample-counts");
    if (!counts) return fail(counts.error().message);
    sampleCounts = std::move(counts.value());
  }
  CompareRequest request;
  request.methods = splitCommaList(a.methods);
  request.budgets = splitCommaList(a.budgets);
  if (!a.composite.empty()) request.rules = splitCommaList(a.composite);
  request.maxPeels = a.maxPeels;
  request.modelPath = a.model;
  request.capture = a.capture;
  request.pixelsPerDegree = a.pixelsPerDegree;
  request.seed = a.scene.seed;
  request.sampleStorage = a.scene.storage() == SampleStorage::Sample ? "sample" : "pixel";
  request.repeat = a.repeat;
  request.warmup = a.warmup;
  auto checked = checkCompareRequest(request);
  if (!checked) return fail(checked.error().message);
  CompareOptions options = std::move(checked.value());
  options.scene = a.scene.source;

  // output folder: checked and its staging folder made before any work; put in place at the end
  auto outFolder = OutputFolder::begin(a.out);
  if (!outFolder) return fail(outFolder.error().message);
  const fs::path dir(a.out);

  auto memoryLimit = a.scene.memoryLimitBytes();
  if (!memoryLimit) return fail(memoryLimit.error().message);
  options.memoryLimitBytes = memoryLimit.value();
  auto engine = makeSceneEngine(a.scene);
  if (!engine) return fail(engine.error().message);
  EngineOptions engineOptions;
  engineOptions.threads = a.scene.threads;
  auto truthEngine = makeTruthEngine(a.truthEngine, **engine, engineOptions, options);
  if (!truthEngine) return fail(truthEngine.error().message);
  // the ground truth's (the A-buffer's) buffers at this size, before the scene is loaded
  if (auto fits = checkComparisonFits(**engine, a.scene.width, a.scene.height, options); !fits)
    return fail(echoPath(a.scene.source) + ": " + fits.error().message);

  Progress progress(!a.scene.quiet);
  progress.set("loading " + a.scene.source);
  auto prepared = prepareScene(a.scene);
  if (!prepared) return fail(prepared.error().message);
  options.background = prepared->scene.background;
  if (temporal)
    return runTemporal(a, options, version, **engine, *prepared, progress, outFolder.value());
  progress.set("setting up " + a.scene.source);
  auto view = prepareComparedView(
      **engine, sceneView(*prepared, a.scene, prepared->cameras.front()), options);
  if (!view) return fail(echoPath(a.scene.source) + ": " + view.error().message);
  // --orbit-view I: view I - 1 precedes it (vkb's Fresnel term)
  auto previous = previousViewCosine(**engine, prepared->scene, a.scene.source,
                                     {prepared->cameras, prepared->previousCamera}, a.scene.width,
                                     a.scene.height, a.scene.sampleCount());
  if (!previous) return fail(previous.error().message);
  options.previousNearestCosine = std::move(previous.value());
  options.progress = [&progress](const std::string& stage, int done, int total) {
    progress.set(stage, done, total);
  };
  auto result = runComparison(**engine, *view->view, options, view->truth.get());
  if (!result) return fail(echoPath(a.scene.source) + ": " + result.error().message);
  // --sample-counts: the same comparison at each count, against that count's own ground truth
  if (auto counted =
          addSampleCounts(**engine, sceneView(*prepared, a.scene, prepared->cameras.front()),
                          options, sampleCounts, *result);
      !counted)
    return fail(echoPath(a.scene.source) + ": " + counted.error().message);
  const CompareResult& r = result.value();

  // files
  progress.set("writing " + a.out);
  const auto [versionNumber, info] = provenance(version);
  auto written = writeComparison(r, outFolder->staging(), versionNumber, info);
  if (!written) return fail(written.error().message);
  if (auto placed = outFolder->commit(); !placed) return fail(placed.error().message);
  const std::string& jsonText = written.value();
  progress.clear();

  if (!a.scene.quiet) {
    if (!r.truthNote.empty()) std::fprintf(stderr, "note: %s\n", r.truthNote.c_str());
    printSummary(r);
    std::fprintf(stderr, "report: %s\n", echoPath((dir / "report.html").string()).c_str());
  }
  if (a.scene.json) std::fputs(jsonText.c_str(), stdout);
  if (auto ran = checkSomeRunRan(r); !ran)
    return fail(echoPath(a.scene.source) + ": " + ran.error().message + "; the refusals are in " +
                echoPath(a.out));
  return 0;
}

}  // namespace

Runner addCompareCommand(CLI::App& app) {
  auto args = std::make_shared<CompareArgs>();
  CLI::App* cmd = app.add_subcommand(
      "compare",
      "Render the ground truth and several methods at several budgets; write images, metrics "
      "(results.json, results.csv) and an HTML report");
  args->scene.add(*cmd, true, true);
  cmd->add_option("--budget,--budgets,-M", args->budgets,
                  "Memory budgets, comma-separated, e.g. 20MB,40MB (MB = 2^20 bytes) or 25%,50% "
                  "(each method's per-pixel words + that share of the exact A-buffer's node "
                  "bytes); lists may mix both; auto: log-spaced from the listed methods' "
                  "smallest budget to the exact A-buffer's (mfr info --methods; the default)");
  cmd->add_option("--methods,-m", args->methods,
                  "Methods, comma-separated (default " + args->methods + "). " + presetHelp());
  cmd->add_option("--out,-o", args->out, "Output folder (created if missing)")->required();
  cmd->add_option("--composite", args->composite,
                  "Compositing rules, comma-separated (kbuffer, hybrid): every method that takes "
                  "a rule runs under each, the oracle (optimal) too, each row labelled with its "
                  "rule (default kbuffer,hybrid; the peer methods keep their own rule)");
  cmd->add_option("--repeat", args->repeat,
                  "Timed renders per run (default 3): the table shows the median time, results "
                  "the min and max");
  cmd->add_option("--warmup", args->warmup, "Untimed renders before the timed ones (default 1)");
  cmd->add_option("--truth-engine", args->truthEngine,
                  "Engine of the ground truth, cpu or gl (default: the comparison's own; on the "
                  "gl engine the cpu engine takes over, with a note, when the GPU's limits refuse "
                  "the A-buffer)");
  cmd->add_option("--capture", args->capture, "tile (default) or parallel");
  cmd->add_option("--max-peels", args->maxPeels,
                  "Depth peeling (peel, dual-peel): at most P geometry passes; the rest dropped, "
                  "or with --composite hybrid blended into a tail (default: until none remains)");
  cmd->add_option("--model", args->model,
                  "Deep k-buffer model (.mfrnn, from mfr train; default: the built-in model)");
  cmd->add_option("--ppd", args->pixelsPerDegree, "FLIP pixels per degree (default 67.02)");
  cmd->add_option("--sample-counts", args->sampleCounts,
                  "Sample counts, comma-separated (1, 2, 4, 8): also run the comparison at each, "
                  "against its own per-sample ground truth, and plot every method's error "
                  "against bytes per pixel per count in the report (results.json "
                  "sample_counts)");
  cmd->add_option("--orbit-step", args->orbitStep,
                  "With --orbit N (temporal comparison): degrees between consecutive frames "
                  "(default 360 / N)");
  const CLI::App* root = &app;
  return [args, root] { return run(*args, root->version()); };
}

}  // namespace mfr::cli
