// The deep k-buffer's network file as the method needs it (DHOIT sec. 3.2): the checks a model
// must pass (12 inputs, 1 output, the feature set and target this build computes) and the model
// shipped in the repository. Backend-neutral: every engine runs the same model.
#pragma once

#include <memory>
#include <string>

#include "mfr/core/result.hpp"
#include "mfr/method/method.hpp"

namespace mfr {

namespace learn {
struct Model;
}

/// Checks that a model fits the deep k-buffer: 12 inputs, 1 output, metadata declaring the feature
/// set kDkbFeatureSet ("features") and, if it declares a target ("target"), the target definition
/// learn::kDkbTargetScaling. `name` names the model in the message.
Result<void> checkDkbModel(const learn::Model& model, const std::string& name);

/// The model shipped in the repository (models/dkb-default.mfrnn, compiled into the library),
/// decoded once. An error when the build had no model file, or when the model does not declare
/// both kDkbFeatureSet and learn::kDkbTargetScaling (stale against the code: retrain it).
Result<std::shared_ptr<const learn::Model>> builtinDkbModel();

/// The model a deep k-buffer method runs: its own (MethodDesc::model, checked with
/// checkDkbModel) or else the built-in one. Both engines take it from here.
Result<std::shared_ptr<const learn::Model>> dkbModelFor(const MethodDesc& method);

}  // namespace mfr
