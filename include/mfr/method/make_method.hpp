// A method from a preset and the user's adjustments: the one place that validates method options
// (which presets take which option, method_options.hpp; their ranges; the model's fit). The
// command line, the Python module and the viewer describe what the user set in MethodOverrides
// and call makeMethod, so the three cannot drift; errors name the option as the caller spells it
// (mfr/core/option_name.hpp).
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "mfr/core/option_name.hpp"
#include "mfr/core/result.hpp"
#include "mfr/method/importance.hpp"
#include "mfr/method/method.hpp"
#include "mfr/method/render_output.hpp"

namespace mfr {

namespace learn {
struct Model;
}

/// The variable k-buffer's importance parameters the user set (Eqs. 3-6, importance.hpp); unset
/// ones keep ImportanceParams' defaults.
struct ImportanceOverrides {
  std::optional<double> alpha;               // --importance-alpha, in [0, 1]
  std::optional<double> nLimit;              // --n-limit, in [1, 1e6]
  std::optional<double> peripheryD;          // --periphery-d, in (0, 100]
  std::optional<double> noise;               // --noise, in [0, 1]
  std::optional<std::vector<double>> fovea;  // --fovea X,Y: two finite pixel coordinates
  std::optional<bool> depthTerm, peripheryTerm, fresnelTerm, noiseTerm;  // --no-*-term
  /// Set by a front end that takes the parameters as one argument (Python's importance dict):
  /// given, even when empty.
  bool asGroup = false;
  /// The first parameter set, as the CLI spells it (empty: none): the one an error names when the
  /// method has no heuristic importance.
  std::string firstGiven() const;
  /// Every parameter set to `params`' value (the viewer's panel holds a whole ImportanceParams).
  static ImportanceOverrides all(const ImportanceParams& params);
};

/// What the user set on top of a preset. Unset fields keep the preset's value.
struct MethodOverrides {
  std::optional<int64_t> k;                   // --k, in [1, 2^20]
  std::string composite;                      // --composite kbuffer|hybrid (empty: the preset's)
  std::optional<int64_t> occupancyD;          // --occupancy-d, in [1, 64]
  std::optional<int64_t> maxPeels;            // --max-peels, in [1, 65536] (peel, dual-peel)
  std::string modelPath;                      // --model: a .mfrnn file (empty: none)
  std::shared_ptr<const learn::Model> model;  // or a model already in memory (mfr.Model)
  std::string modelName = "(mfr.Model)";      // how errors name `model`
  ImportanceOverrides importance;
  uint64_t seed = 1;  // the heuristic importance's noise seed (the scene's --seed)
  /// The viewer keeps its panel's settings when the method changes: options the method does not
  /// take are ignored instead of refused.
  bool ignoreInapplicable = false;
};

/// The preset `name` with the overrides applied, after every check: an option the method does not
/// take is an error naming the option, the method and the presets that take it; a value out of
/// range names the option and its range; a model that does not fit the method names the model.
Result<MethodDesc> makeMethod(const std::string& name, const MethodOverrides& overrides,
                              Spelling spelling = Spelling::Cli);

/// The render options every front end takes as text, checked once: --capture tile|parallel and
/// --memory-limit SIZE (bytes of parseByteSize), errors in the caller's spelling. A budget is a
/// BudgetSpec (parseBudgetSpec: a size or a share of the A-buffer).
Result<CaptureMode> parseCaptureOption(const std::string& text, Spelling spelling = Spelling::Cli);
Result<uint64_t> parseMemoryLimitOption(const std::string& text, Spelling spelling = Spelling::Cli);

/// Reads a deep k-buffer model file (an importance model for dkb / dkb-fill or a curve model for
/// dkb-curve); errors name the path.
Result<std::shared_ptr<const learn::Model>> loadMethodModel(const std::string& path);

/// A comparison's --model must be used by one of its `methods` (presets), not silently ignored:
/// else an error naming the option and the presets that take it.
Result<void> checkModelUsed(const std::vector<std::string>& methods,
                            Spelling spelling = Spelling::Cli);

/// Each of a comparison's `methods` that takes a model must be able to run `model` under
/// `compositing` (the comparison's rule when it sets one; checkModelForMethod). `name` names the
/// model in errors.
Result<void> checkComparisonModel(const learn::Model& model, const std::string& name,
                                  const std::vector<std::string>& methods,
                                  std::optional<Compositing> compositing,
                                  Spelling spelling = Spelling::Cli);

}  // namespace mfr
