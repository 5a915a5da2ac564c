// What a user asks `mfr compare` (and Python's mfr.compare) for, in the user's own words, checked
// once for both faces: the method and budget lists, the compositing rules, --max-peels, the model,
// the capture, FLIP's pixels per degree, the sample storage and the timing repeats. Errors are one
// line and name the option as the face spells it (Spelling: "--methods" or "methods").
//
// The defaults are the fair ones (docs/COMPARE.md): every method that takes a choice of rule runs
// under both kbuffer and hybrid compositing, the oracle under each, and every run is timed
// `repeat` times after `warmup` untimed renders.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "mfr/compare/compare.hpp"
#include "mfr/core/option_name.hpp"
#include "mfr/core/result.hpp"

namespace mfr {

/// `mfr compare`'s default method list (Python: mfr.DEFAULT_COMPARE_METHODS).
extern const char* const kDefaultCompareMethods;

struct CompareRequest {
  std::vector<std::string> methods;           // preset names (empty entries are refused)
  std::vector<std::string> budgets;           // "20MB", "25%", a byte count; or the one word "auto"
  std::vector<std::string> rules;             // --composite: kbuffer, hybrid; empty: both
  std::optional<int64_t> maxPeels;            // --max-peels (peel, dual-peel)
  std::string modelPath;                      // --model FILE (empty: none, or `model`)
  std::shared_ptr<const learn::Model> model;  // a model given as an object (Python)
  std::string modelName;                      // how errors name `model`
  std::string capture = "tile";
  double pixelsPerDegree = kFlipDefaultPixelsPerDegree;
  uint64_t seed = 1;
  std::string sampleStorage = "pixel";
  int64_t repeat = 3;  // timed renders per run
  int64_t warmup = 1;  // untimed renders before them
};

/// The options of runComparison for `request` (scene, background, progress, memory limit, truth
/// engine and view cosine are the caller's). Budgets "auto" sets autoBudgets and no budget.
Result<CompareOptions> checkCompareRequest(const CompareRequest& request,
                                           Spelling spelling = Spelling::Cli);

/// The engine of `--truth-engine NAME` for a comparison on `engine`, set in options.truthEngine
/// (the caller keeps it alive): NAME empty, a CPU engine as a fallback (truthFallback) when
/// `engine` is not the CPU engine, for a ground truth the GPU's limits refuse; NAME the engine's
/// own: none. Errors: an unknown name (naming the option).
Result<std::unique_ptr<Engine>> makeTruthEngine(const std::string& name, const Engine& engine,
                                                const EngineOptions& engineOptions,
                                                CompareOptions& options,
                                                Spelling spelling = Spelling::Cli);

/// "kbuffer,hybrid" -> the rules; "" -> none (the default: both). Errors name the option.
Result<std::vector<Compositing>> parseCompositingRules(const std::vector<std::string>& names,
                                                       Spelling spelling = Spelling::Cli);

/// A comma-separated list, each item trimmed of blanks ("a, b" -> {"a", "b"}; "" -> {""}).
std::vector<std::string> splitCommaList(const std::string& text);

}  // namespace mfr
