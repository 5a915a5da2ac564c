// renderViews (render_views.hpp).
#include "mfr/engine/render_views.hpp"

#include "mfr/core/quote.hpp"
#include "mfr/method/memory_model.hpp"
#include "mfr/method/pass_plan.hpp"

namespace mfr {

Result<std::vector<float>> previousViewCosine(Engine& engine, const Scene& scene,
                                              const std::string& source, const SceneViews& views,
                                              int width, int height, int samples) {
  if (!views.previousCamera) return std::vector<float>{};
  const auto named = [&](const Error& e) { return makeError(echoPath(source) + ": " + e.message); };
  auto previous = engine.prepare(View{&scene, *views.previousCamera, width, height, samples});
  if (!previous) return named(previous.error());
  auto cosine = engine.nearestCosine(**previous);
  if (!cosine) return named(cosine.error());
  return std::move(cosine.value());
}

Result<void> renderViews(Engine& engine, const Scene& scene, const std::string& source,
                         const SceneViews& views, int width, int height, int samples,
                         const MethodDesc& method, RenderOptions options,
                         const std::optional<BudgetSpec>& budget,
                         const std::function<Result<void>(const RenderedView&)>& each) {
  const auto named = [&](const Error& e) { return makeError(echoPath(source) + ": " + e.message); };
  const auto viewOf = [&](const Camera& camera) {
    return View{&scene, camera, width, height, samples};
  };
  if (budget) options.budgetBytes = budget->bytes;
  std::vector<float> previousCosine;  // importance methods: nearest |n.v| of the previous view
  if (method.allocation == AllocationPolicy::Importance &&
      method.importanceSource == ImportanceSource::Heuristic) {
    auto cosine = previousViewCosine(engine, scene, source, views, width, height, samples);
    if (!cosine) return cosine.error();
    previousCosine = std::move(cosine.value());
  }
  const std::string size = std::to_string(width) + "x" + std::to_string(height);
  for (size_t v = 0; v < views.cameras.size(); ++v) {
    auto view = engine.prepare(viewOf(views.cameras[v]));
    if (!view) return named(view.error());
    options.previousNearestCosine = previousCosine.empty() ? nullptr : &previousCosine;
    if (budget && budget->isRelative()) {
      auto counted = engine.countFragments(**view);
      if (!counted) return named(counted.error());
      FrameCounts counts = FrameCounts::of(counted.value());
      // the pixels the per-pixel words are kept for (per sample under per-sample storage)
      counts.pixels = (*view)->storagePixels(sampleStorageOf(method, options));
      auto bytes =
          resolveBudget(*budget, method, engine.memoryModel(method, options), counts, size);
      if (!bytes) return named(bytes.error());
      options.budgetBytes = bytes.value();
    }
    auto result = engine.render(**view, method, options);
    if (!result) return named(result.error());
    result->stats.primitivesSkipped = scene.primitivesSkipped;
    previousCosine = result->nearestCosine;
    MFR_TRY(each(RenderedView{static_cast<int>(v), **view, result.value()}));
  }
  return {};
}

}  // namespace mfr
