// The deep k-buffer's network file as the method needs it (DHOIT sec. 3.2): the checks a model
// must pass (12 inputs, 1 output, the feature set and target this build computes, the compositing
// rule its targets were computed for) and the models shipped in the repository, one per rule
// (issue 14 sec. 3). Backend-neutral: every engine runs the same model.
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

/// Checks that a model fits dkb-curve (mfr/method/dkb_curve.hpp): 12 inputs, 9 outputs, the
/// feature set kDkbFeatureSet and, if declared, the target kDkbCurveTargetScaling.
Result<void> checkDkbCurveModel(const learn::Model& model, const std::string& name);

/// The compositing rule whose optimal allocations a model was trained on: its metadata's
/// "composite" ("hybrid" or "kbuffer"); a model that does not declare one predates per-rule
/// models, whose targets were all hybrid, and is Hybrid. Errors: a declared value that is not a
/// k-buffer family rule (`name` names the model).
Result<Compositing> dkbModelRule(const learn::Model& model, const std::string& name);

/// Error unless the model was trained for `rule` (dkbModelRule): a one-line message naming the
/// model (`name`), both rules and the fix.
Result<void> checkDkbModelRule(const learn::Model& model, const std::string& name,
                               Compositing rule);

/// The model shipped in the repository for `rule` (kbuffer: models/dkb-kbuffer.mfrnn, hybrid:
/// models/dkb-default.mfrnn, both compiled into the library), decoded once. An error when the
/// build had no such model file, when the rule is not kbuffer or hybrid, or when the model does not
/// declare kDkbFeatureSet, learn::kDkbTargetScaling and `rule` (stale against the code: retrain).
Result<std::shared_ptr<const learn::Model>> builtinDkbModel(Compositing rule = Compositing::Hybrid);

/// Error unless `model` can run `method` (a deep k-buffer method): the fit (checkDkbModel, or
/// checkDkbCurveModel for dkb-curve) and the rule (checkDkbModelRule against its compositing).
Result<void> checkModelForMethod(const learn::Model& model, const std::string& name,
                                 const MethodDesc& method);

/// dkb-curve's shipped model for `rule` (hybrid: models/dkb-curve.mfrnn, kbuffer:
/// models/dkb-curve-kbuffer.mfrnn), with the same checks as builtinDkbModel's.
Result<std::shared_ptr<const learn::Model>> builtinDkbCurveModel(
    Compositing rule = Compositing::Hybrid);

/// The model a deep k-buffer method runs: its own (MethodDesc::model, checked with checkDkbModel
/// and against the method's compositing rule: a model trained for the other rule is an error) or
/// else the built-in one matching the method's compositing; for dkb-curve (MethodDesc::
/// predictedCurves) a curve model. Both engines take it from here.
Result<std::shared_ptr<const learn::Model>> dkbModelFor(const MethodDesc& method);

}  // namespace mfr
