// One method over the views of a request (one camera, or an orbit): what `mfr render` and
// mfr.render share. Between frames it carries what a sequence carries: the variable k-buffer's
// previous-frame |n.v| (with --orbit-view I, view I - 1 is rendered for it first, as in the full
// orbit), and a relative budget (a share of the A-buffer) is resolved on each view's count pass.
#pragma once

#include <functional>
#include <optional>
#include <string>

#include "mfr/core/result.hpp"
#include "mfr/engine/engine.hpp"
#include "mfr/method/budget_spec.hpp"
#include "mfr/scene/scene_request.hpp"

namespace mfr {

/// What a view's render hands to the caller.
struct RenderedView {
  int index = 0;  // of the views rendered
  const PreparedView& view;
  RenderOutput& output;
};

/// With --orbit-view I > 0: the nearest |n.v| of view I - 1 (SceneViews::previousCamera), the
/// previous frame the variable k-buffer's Fresnel term reads; empty without a previous camera.
/// Errors are prefixed with the scene `source`.
Result<std::vector<float>> previousViewCosine(Engine& engine, const Scene& scene,
                                              const std::string& source, const SceneViews& views,
                                              int width, int height, int samples = 1);

/// Renders `method` on every view of `views` (at width x height, `samples` per pixel) with
/// `options`; `budget`, when given, replaces options.budgetBytes (a share resolved per view: of the
/// per-sample A-buffer when multisampled). `each` receives each output in view order; its error
/// stops the run. Engine errors are prefixed with the scene `source`.
Result<void> renderViews(Engine& engine, const Scene& scene, const std::string& source,
                         const SceneViews& views, int width, int height, int samples,
                         const MethodDesc& method, RenderOptions options,
                         const std::optional<BudgetSpec>& budget,
                         const std::function<Result<void>(const RenderedView&)>& each);

}  // namespace mfr
