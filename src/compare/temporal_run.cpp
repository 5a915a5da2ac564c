// runTemporalComparison (temporal_run.hpp).
#include "mfr/compare/temporal_run.hpp"
#include "mfr/core/json_limits.hpp"

#include <cstdio>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "mfr/compare/compare_output.hpp"
#include "mfr/core/atomic_file.hpp"
#include "mfr/core/image.hpp"
#include "mfr/core/quote.hpp"

namespace mfr {
namespace {

namespace fs = std::filesystem;

// the images of one frame as the temporal report shows them: the ground truth's, then each run's
// in the order of TemporalResult::series (budgets, then methods; empty: the run failed)
std::vector<std::string> frameImages(const CompareResult& frame) {
  std::vector<std::string> files = {frame.groundTruth.imageFile};
  for (const CompareBudget& cb : frame.budgets)
    for (const CompareRun& run : cb.runs) files.push_back(run.ok() ? run.imageFile : "");
  return files;
}

}  // namespace

Result<TemporalRun> runTemporalComparison(Engine& engine, const TemporalRequest& r,
                                          CompareOptions options, const std::string& dirText) {
  const auto named = [&](const Error& e) {
    return makeError(echoPath(r.source) + ": " + e.message);
  };
  TemporalRun run;
  run.stepDegrees = r.stepDegrees > 0.0f ? r.stepDegrees : 360.0f / static_cast<float>(r.frames);
  const std::vector<Camera> path = orbitPath(r.start, r.frames, run.stepDegrees);
  const fs::path dir(dirText);
  TemporalStability temporal(options.flipPixelsPerDegree);
  TemporalReportPage page;
  std::vector<std::string>& folders = page.frameFolders;
  std::vector<float> previousCosine;  // vkb's Fresnel term: the previous frame's nearest |n.v|
  std::string engineName;
  for (int f = 0; f < r.frames; ++f) {
    auto view =
        prepareComparedView(engine, View{r.scene, path[f], r.width, r.height, r.samples}, options);
    if (!view) return named(view.error());
    options.previousNearestCosine = previousCosine;
    options.progress = [&r, f](const std::string& stage, int done, int total) {
      if (r.progress)
        r.progress("frame " + std::to_string(f + 1) + "/" + std::to_string(r.frames) + ": " + stage,
                   done, total);
    };
    auto result = runComparison(engine, *view->view, options, view->truth.get());
    if (!result) return named(result.error());
    options.budgets = budgetSpecs(result.value());  // --budget auto: the first frame's, for all
    options.autoBudgets = false;
    engineName = result->engine;
    char folder[32];
    std::snprintf(folder, sizeof folder, "frame_%03d", f);
    folders.push_back(folder);
    MFR_TRY(prepareOutputFolder((dir / folder).string()));
    auto written =
        writeComparison(result.value(), (dir / folder).string(), r.versionNumber, r.info);
    if (!written) return written.error();
    MFR_TRY(temporal.add(result.value()));
    page.frameImages.push_back(frameImages(result.value()));
    auto cosine = engine.nearestCosine(*view->view);
    if (!cosine) return named(cosine.error());
    previousCosine = std::move(cosine.value());
  }
  run.result = temporal.result();
  nlohmann::json j;
  j["mfr_version"] = r.versionNumber;
  j["scene"] = r.source;
  j["engine"] = engineName;
  j["width"] = r.width;
  j["height"] = r.height;
  j["orbit"] = r.frames;
  j["orbit_step_degrees"] = run.stepDegrees;
  j["frames"] = folders;
  j["temporal"] = temporalToJson(run.result);
  // a path that is not UTF-8: U+FFFD in the JSON, as compare_output.cpp
  run.jsonText = jsonText(j) + "\n";
  MFR_TRY(writeFileAtomically((dir / "results.json").string(), run.jsonText));
  MFR_TRY(writeFileAtomically((dir / "results.csv").string(), temporalToCsv(run.result)));
  page.scene = r.source;
  page.width = r.width;
  page.height = r.height;
  page.stepDegrees = run.stepDegrees;
  page.commandLine = r.info.commandLine;
  page.mfrVersion = r.info.mfrVersion;
  page.generated = r.info.generated;
  MFR_TRY(
      writeFileAtomically((dir / "report.html").string(), temporalReportHtml(run.result, page)));
  return run;
}

}  // namespace mfr
