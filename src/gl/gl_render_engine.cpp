// The GL engine behind the Engine seam (mfr/gl/gl_render_engine.hpp). The k of a fixed-k method
// and the budget checks come from the shared allocate() or, for the counted, dynamic and
// importance-map k computed in compute shaders, from its checks of the GPU's totals (boundedK,
// checkBoundedSlots, checkCoveredPixels: the same errors as the CPU engine); the
// memory charged is MemoryModel's (a lock word per pixel for the fixed-k stores, which take the
// per-pixel spin-lock; the A-buffer appends with atomics); what GL allocated is bytes_allocated.
#include "mfr/gl/gl_render_engine.hpp"

#include <algorithm>
#include <chrono>
#include <utility>

#include "mfr/cpu/dkb_curve_pass.hpp"
#include "mfr/cpu/optimal_oracle.hpp"
#include "mfr/cpu/raster_frame.hpp"
#include "mfr/gl/gl_context.hpp"
#include "mfr/gl/gl_engine.hpp"
#include "mfr/learn/model_file.hpp"
#include "mfr/method/allocation.hpp"
#include "mfr/method/dkb_model.hpp"
#include "mfr/method/importance.hpp"
#include "mfr/method/memory_model.hpp"
#include "mfr/method/optimal_allocation.hpp"

namespace mfr::gl {
namespace {

class GlView final : public PreparedView {
 public:
  GlView(GlEngine engine, const View& view) : engine_(std::move(engine)), view_(view) {}
  int width() const override { return engine_.width(); }
  int height() const override { return engine_.height(); }
  GlEngine& engine() const { return engine_; }
  const View& view() const { return view_; }  // for the CPU oracle of the optimal k-buffer
  /// True the first time: the first render of a view warms up (shader compilation, llvmpipe's
  /// first-frame timer values), later ones are timed as they run.
  bool firstRender() const { return std::exchange(first_, false); }

 private:
  mutable GlEngine engine_;  // rendering changes GL state, not the view
  View view_;
  mutable bool first_ = true;
};

double msSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// The optimal k-buffer's k(p) from the CPU engine's oracle (optimalK, mfr/cpu/optimal_oracle.hpp)
// on the same view.
Result<OracleChoice> cpuOracle(const View& view, const MethodDesc& method,
                               const RenderOptions& options, uint64_t slots) {
  RasterOptions ro;
  ro.width = view.width;
  ro.height = view.height;
  auto frame = RasterFrame::build(*view.scene, view.camera, ro);
  if (!frame) return frame.error();
  return optimalK(*frame, method, options, slots);
}

// dkb-curve's n(p) and k(p) from the CPU engine's passes (predictedCurveK,
// mfr/cpu/dkb_curve_pass.hpp) on the same view.
Result<CurveChoice> cpuCurves(const View& view, const MethodDesc& method, uint64_t slots) {
  RasterOptions ro;
  ro.width = view.width;
  ro.height = view.height;
  auto frame = RasterFrame::build(*view.scene, view.camera, ro);
  if (!frame) return frame.error();
  return predictedCurveK(*frame, method, slots);
}

class GlRenderEngine final : public Engine {
 public:
  GlRenderEngine(GlContext context, bool interlock)
      : context_(std::move(context)), interlock_(interlock) {}

  std::string_view name() const override { return "gl"; }

  std::map<std::string, std::string> describe() const override {
    const GlExtensions& c = context_.extensions();
    const auto yes = [](bool b) { return std::string(b ? "yes" : "no"); };
    return {{"engine", "gl"},
            {"renderer", context_.renderer()},
            {"version", context_.version()},
            {"vendor", context_.vendor()},
            {"egl_platform", context_.eglPlatform()},
            // the k-buffer capture: per-pixel spin-lock (imageAtomicExchange loop) or interlock
            {"sync", interlock_ ? "interlock (" + interlockExtension(context_) + ")" : "lock"},
            {"GL_ARB_fragment_shader_interlock", yes(c.arbFragmentShaderInterlock)},
            {"GL_NV_fragment_shader_interlock", yes(c.nvFragmentShaderInterlock)},
            {"GL_INTEL_fragment_shader_ordering", yes(c.intelFragmentShaderOrdering)},
            {"GL_ARB_gpu_shader_int64", yes(c.arbGpuShaderInt64)},
            {"GL_NV_shader_atomic_int64", yes(c.nvShaderAtomicInt64)},
            // the fixed-k k-buffer without tail or occupancy: 64-bit atomicMin or the lock
            {"fixed_k_capture", hasAtomic64(context_) ? "atomic64" : "lock"}};
  }

  Result<std::unique_ptr<PreparedView>> prepare(const View& view) override {
    if (!view.scene) return makeError("engine gl: a view without a scene");
    auto engine =
        GlEngine::create(context_, *view.scene, view.camera, view.width, view.height, interlock_);
    if (!engine) return engine.error();
    return std::unique_ptr<PreparedView>(std::make_unique<GlView>(std::move(engine.value()), view));
  }

  Result<RenderOutput> render(const PreparedView& view, const MethodDesc& methodIn,
                              const RenderOptions& options) override {
    const auto* gv = dynamic_cast<const GlView*>(&view);
    if (!gv) return makeError("engine gl: the view was prepared by another engine");
    const PixelLayout layout{view.width(), view.height(), 0};  // row-major prefix sums on GL
    const uint64_t pixels = layout.pixels();
    MethodDesc method = methodIn;
    const bool fixedK = method.allocation == AllocationPolicy::FixedK;
    const bool accumulates = method.allocation == AllocationPolicy::NoNodes;
    // variable k (counted, dynamic, importance, optimal): n(p) [and I(p) or the oracle's k(p)]
    // measured first, k(p) and offsets from the shared allocate() on the host, then the GL
    // capture and resolve with that allocation
    const bool variable = method.allocation == AllocationPolicy::CountedK ||
                          method.allocation == AllocationPolicy::DynamicK ||
                          method.allocation == AllocationPolicy::Importance ||
                          method.allocation == AllocationPolicy::Optimal;
    const bool deep = method.allocation == AllocationPolicy::Importance &&
                      method.importanceSource == ImportanceSource::Network;
    // the GL k-buffers take the per-pixel spin-lock: the CPU engine's fragment-parallel memory
    // (wboit's accumulators too)
    const MemoryModel memory =
        MemoryModel::of(method, /*fragmentParallel=*/fixedK || variable || accumulates);
    if (fixedK) {  // k from the budget (or explicit), checked as on the CPU engine
      auto a = allocate(layout, method, memory, options.budgetBytes, {}, {}, {});
      if (!a) return a.error();
      method.k = a->globalK;
    }
    std::vector<PassTime> hostPasses;
    RenderOutput out;
    std::optional<Allocation> perPixel;
    std::vector<uint32_t> n;  // variable k: n(p) measured first, reused by the frame
    // counted, dynamic and importance-map k: count, histogram, importance, k(p), prefix sum in
    // compute shaders; the host reads a few totals and checks them with allocate()'s words
    const bool onDevice =
        method.allocation == AllocationPolicy::CountedK ||
        method.allocation == AllocationPolicy::DynamicK ||
        (method.allocation == AllocationPolicy::Importance &&
         method.importanceSource != ImportanceSource::Network && !method.fillUnusedSlots);
    std::optional<uint32_t> deviceGlobalK;
    if (onDevice) {
      MFR_TRY(budgetSlots(layout, method, memory, options.budgetBytes));  // before any pass
      std::vector<GlPassTime> passes;
      auto summary = gv->engine().countOnDevice(&passes);
      if (!summary) return summary.error();
      if (method.allocation == AllocationPolicy::Importance) {
        MFR_TRY(checkCoveredPixels(layout, method, memory, options.budgetBytes, summary->covered));
        const uint64_t slots = memory.fragmentSlots(*options.budgetBytes, pixels);
        static const std::vector<float> none;
        const std::vector<float>& previous =
            options.previousNearestCosine && options.previousNearestCosine->size() == pixels
                ? *options.previousNearestCosine
                : none;
        auto totals = gv->engine().allocateByImportance(method.importance, previous, slots,
                                                        method.store, &passes);
        if (!totals) return totals.error();
        // floor(P(p) F(M)) sums to at most F(M) with IEEE double arithmetic (as on the host);
        // a driver whose double division rounds otherwise could exceed it by a few slots
        if (totals->reservedSlots > slots)
          return makeError("--engine gl: " + method.name +
                           ": the GPU's importance allocation took " +
                           std::to_string(totals->reservedSlots) + " slots of " +
                           std::to_string(slots) + " (double arithmetic not IEEE on this driver)");
      } else {
        auto k = boundedK(layout, method, memory, options.budgetBytes, *summary);
        if (!k) return k.error();
        auto totals = gv->engine().allocateCapped(*k, method.store, &passes);
        if (!totals) return totals.error();
        MFR_TRY(checkBoundedSlots(layout, method, memory, options.budgetBytes, *k, totals->slots));
        deviceGlobalK = *k;
      }
      for (const GlPassTime& t : passes) hostPasses.push_back({t.name + " (allocation)", t.wallMs});
    } else if (variable) {
      std::vector<uint32_t> oracleK;
      auto t0 = std::chrono::steady_clock::now();
      if (method.allocation == AllocationPolicy::Optimal && options.budgetBytes &&
          method.predictedCurves) {  // dkb-curve: features, network and hull on the host
        auto chosen =
            cpuCurves(gv->view(), method, memory.fragmentSlots(*options.budgetBytes, pixels));
        if (!chosen) return chosen.error();
        n = std::move(chosen->n);
        oracleK = std::move(chosen->k);
        hostPasses.push_back({"curves (cpu)", msSince(t0)});
      } else if (method.allocation == AllocationPolicy::Optimal && options.budgetBytes) {
        auto chosen = cpuOracle(gv->view(), method, options,
                                memory.fragmentSlots(*options.budgetBytes, pixels));
        if (!chosen) return chosen.error();
        n = std::move(chosen->n);
        oracleK = std::move(chosen->k);
        out.stats.oracle = std::move(chosen->report);
        hostPasses.push_back({"oracle (cpu)", msSince(t0)});
      } else {
        auto counted = gv->engine().count();
        if (!counted) return counted.error();
        n = std::move(counted.value());
        hostPasses.push_back({"count (n(p) read back)", msSince(t0)});
      }
      if (deep) {  // the deep k-buffer: features and network on GL (dkb_infer.comp)
        if (!options.budgetBytes) return makeError(method.name + ": needs a budget");
        auto resolved = dkbModelFor(method);
        if (!resolved) return resolved.error();
        const std::shared_ptr<const learn::Model> model = std::move(resolved.value());
        std::vector<float> weights;
        for (size_t l = 0; l < model->net.weights.size(); ++l) {
          const auto& w = model->net.weights[l];
          const auto& b = model->net.biases[l];
          weights.insert(weights.end(), w.data(), w.data() + w.size());  // column-major
          weights.insert(weights.end(), b.data(), b.data() + b.size());
        }
        if (model->net.sizes != learn::kDkbLayers)
          return makeError("--engine gl: " + method.name +
                           ": the GL engine runs 12-128-64-1 networks only");
        std::vector<GlPassTime> dkbPasses;
        auto importance = gv->engine().dkbImportance(
            weights, memory.fragmentSlots(*options.budgetBytes, pixels), &dkbPasses);
        if (!importance) return importance.error();
        out.importance.importance = std::move(importance.value());
        for (const GlPassTime& t : dkbPasses) hostPasses.push_back({t.name, t.wallMs});
      } else if (method.allocation == AllocationPolicy::Importance) {
        t0 = std::chrono::steady_clock::now();
        auto cosine = gv->engine().nearestCosine();
        if (!cosine) return cosine.error();
        out.nearestCosine = std::move(cosine.value());
        hostPasses.push_back({"nearest_normal", msSince(t0)});
        t0 = std::chrono::steady_clock::now();
        const std::vector<float>& previous =
            options.previousNearestCosine && options.previousNearestCosine->size() == pixels
                ? *options.previousNearestCosine
                : out.nearestCosine;
        out.importance =
            computeImportance(layout.width, layout.height, n, previous, method.importance);
        hostPasses.push_back({"importance (host)", msSince(t0)});
      }
      t0 = std::chrono::steady_clock::now();
      auto a = allocate(layout, method, memory, options.budgetBytes, n, out.importance.importance,
                        oracleK);
      if (!a) return a.error();
      perPixel = std::move(a.value());
      hostPasses.push_back({"allocate (host)", msSince(t0)});
    }
    GlRenderOptions go;
    go.background = options.background;
    go.readNodes = options.keepStores;
    go.warmUp = gv->firstRender();
    go.allocation = perPixel ? &*perPixel : nullptr;
    go.deviceAllocation = onDevice;
    // (GL's own n(p) only: the optimal k-buffer's and dkb-curve's come from CPU passes)
    go.counts = n.empty() || method.allocation == AllocationPolicy::Optimal ? nullptr : &n;
    auto gl = gv->engine().render(method, go);
    if (!gl) return gl.error();
    GlRenderOutput& g = gl.value();
    // the A-buffer's slots are its fragments: the budget check needs the count pass's n(p)
    auto a = onDevice   ? gv->engine().readDeviceAllocation()
             : perPixel ? Result<Allocation>(std::move(*perPixel))
                        : allocate(layout, method, memory, options.budgetBytes, g.counts, {}, {});
    if (!a) return a.error();
    if (onDevice) {  // the output's maps, read back
      a->globalK = deviceGlobalK;
      if (method.allocation == AllocationPolicy::Importance) {
        auto maps = gv->engine().readImportance();
        if (!maps) return maps.error();
        out.importance = std::move(maps.value());
        auto cosine = gv->engine().readNearestCosine();
        if (!cosine) return cosine.error();
        out.nearestCosine = std::move(cosine.value());
      }
    }

    out.image = std::move(g.image);
    RenderStats& s = out.stats;
    s.method = method.name;
    s.budgetBytes = options.budgetBytes;
    s.fragmentSlots = a->reservedSlots;
    s.bytesByCategory = memory.breakdown(pixels, a->reservedSlots);
    for (const auto& [category, bytes] : s.bytesByCategory) s.bytesUsed += bytes;
    s.bytesAllocatedByCategory = g.bufferBytes;
    s.bytesAllocated = g.totalBufferBytes();
    s.fragmentsGenerated = g.fragments;
    s.culledOccupancy = g.culledOccupancy;
    s.culledKPlus = g.culledKPlus;
    s.globalK = a->globalK;
    uint32_t kMin = UINT32_MAX, kMax = 0, maxN = 0;
    // the k reported: as allocated (importance may reserve more slots than n(p))
    const std::vector<uint32_t>& reported = a->reservedK.empty() ? a->capacity : a->reservedK;
    for (size_t p = 0; p < pixels; ++p) {
      const uint32_t n = g.counts[p];
      // every store keeps the min(n, k) nearest; wboit's accumulators take every fragment
      s.captured += accumulates ? n : std::min(n, a->capacity[p]);
      if (n == 0) continue;
      ++s.coveredPixels;
      kMin = std::min(kMin, reported[p]);
      kMax = std::max(kMax, reported[p]);
      maxN = std::max(maxN, n);
    }
    s.kMin = s.coveredPixels ? kMin : 0;
    s.kMax = kMax;
    s.lost = s.fragmentsGenerated - s.captured;
    s.maxDepthComplexity = maxN;
    s.meanDepthComplexity =
        s.coveredPixels ? static_cast<double>(g.fragments) / s.coveredPixels : 0.0;
    s.engine = "gl";
    s.passes = std::move(hostPasses);  // the host side of a variable-k allocation first
    for (const GlPassTime& t : g.passes) {
      s.passes.push_back({t.name, t.wallMs});  // llvmpipe's GL_TIME_ELAPSED is not usable
      s.engineCounters["gpu_ms_" + t.name] = t.gpuMs;
    }
    s.engineCounters["sync_interlock"] = interlock_ ? 1 : 0;  // the k-buffer capture's sync
    // the fixed-k capture with 64-bit atomicMin instead of the lock (where the driver has them)
    s.engineCounters["atomic64"] = g.atomic64 ? 1 : 0;
    out.kMap = a->reservedK.empty() ? std::move(a->capacity) : std::move(a->reservedK);
    out.depthComplexity = std::move(g.counts);
    if (options.keepStores) {
      out.nodes = std::move(g.nodes);
      out.offsets = std::move(g.nodeOffsets);
      out.counts = std::move(g.nodeCounts);
    }
    return out;
  }

  Result<std::vector<uint32_t>> countFragments(const PreparedView& view) override {
    auto out = render(view, methodPreset("abuffer").value(), RenderOptions{});
    if (!out) return out.error();
    return std::move(out->depthComplexity);
  }

  Result<std::vector<float>> nearestCosine(const PreparedView& view) override {
    const auto* gv = dynamic_cast<const GlView*>(&view);
    if (!gv) return makeError("engine gl: the view was prepared by another engine");
    return gv->engine().nearestCosine();
  }

 private:
  GlContext context_;
  bool interlock_ = false;
};

}  // namespace

Result<std::unique_ptr<Engine>> makeGlEngine(const std::string& sync) {
  if (sync != "auto" && sync != "lock" && sync != "interlock")
    return makeError("--gl-sync '" + sync + "': expected auto, lock or interlock");
  auto context = GlContext::create();
  if (!context) return context.error();
  const bool offered = !interlockExtension(context.value()).empty();
  if (sync == "interlock" && !offered)
    return makeError(
        "--gl-sync interlock: the driver offers none of GL_ARB_fragment_shader_interlock, "
        "GL_NV_fragment_shader_interlock, GL_INTEL_fragment_shader_ordering (renderer " +
        context->renderer() + ")");
  const bool interlock = sync == "interlock" || (sync == "auto" && offered);
  return std::unique_ptr<Engine>(
      std::make_unique<GlRenderEngine>(std::move(context.value()), interlock));
}

void registerGlEngine() {
  registerEngine("gl", [](const EngineOptions& o) { return makeGlEngine(o.glSync); });
}

}  // namespace mfr::gl
