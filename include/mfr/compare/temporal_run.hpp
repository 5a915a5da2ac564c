// The temporal comparison of `mfr compare --orbit N` and mfr.compare(orbit=N): every frame of an
// orbit path compared against its ground truth (runComparison) into DIR/frame_NNN, the stability
// of each method along the path (temporal.hpp), and DIR/results.json, DIR/results.csv
// (temporalToCsv) and DIR/report.html (its plots inline). The front ends stage DIR and report; the
// work is here once.
#pragma once

#include <functional>
#include <string>

#include "mfr/compare/compare.hpp"
#include "mfr/compare/temporal.hpp"
#include "mfr/core/result.hpp"
#include "mfr/engine/engine.hpp"

namespace mfr {

struct TemporalRequest {
  const Scene* scene = nullptr;
  std::string source;        // names the scene in errors and the report
  Camera start;              // the path's first camera
  int frames = 2;            // at least 2
  float stepDegrees = 0.0f;  // 0: 360 / frames
  int width = 1024, height = 1024;
  int samples = 1;  // per pixel (View::samples)
  std::string versionNumber;
  ReportInfo info;
  /// Called before each step with ("frame F/N: stage", done, total). May be empty.
  std::function<void(const std::string&, int, int)> progress;
};

struct TemporalRun {
  TemporalResult result;
  float stepDegrees = 0.0f;
  std::string jsonText;  // DIR/results.json
};

/// Runs the comparison of `options` (its methods and budgets) on every frame and writes `dir`.
Result<TemporalRun> runTemporalComparison(Engine& engine, const TemporalRequest& request,
                                          CompareOptions options, const std::string& dir);

}  // namespace mfr
