// The GL engine behind the Engine seam (mfr/gl/gl_render_engine.hpp). The k of a fixed-k method
// and the budget checks come from the shared allocate() (the same errors as the CPU engine); the
// memory charged is MemoryModel's (a lock word per pixel for the fixed-k stores, which take the
// per-pixel spin-lock; the A-buffer appends with atomics); what GL allocated is bytes_allocated.
#include "mfr/gl/gl_render_engine.hpp"

#include <algorithm>
#include <utility>

#include "mfr/gl/gl_context.hpp"
#include "mfr/gl/gl_engine.hpp"
#include "mfr/method/allocation.hpp"
#include "mfr/method/memory_model.hpp"

namespace mfr::gl {
namespace {

class GlView final : public PreparedView {
 public:
  explicit GlView(GlEngine engine) : engine_(std::move(engine)) {}
  int width() const override { return engine_.width(); }
  int height() const override { return engine_.height(); }
  GlEngine& engine() const { return engine_; }
  /// True the first time: the first render of a view warms up (shader compilation, llvmpipe's
  /// first-frame timer values), later ones are timed as they run.
  bool firstRender() const { return std::exchange(first_, false); }

 private:
  mutable GlEngine engine_;  // rendering changes GL state, not the view
  mutable bool first_ = true;
};

class GlRenderEngine final : public Engine {
 public:
  explicit GlRenderEngine(GlContext context) : context_(std::move(context)) {}

  std::string_view name() const override { return "gl"; }

  std::map<std::string, std::string> describe() const override {
    const GlExtensions& c = context_.extensions();
    const auto yes = [](bool b) { return std::string(b ? "yes" : "no"); };
    return {{"engine", "gl"},
            {"renderer", context_.renderer()},
            {"version", context_.version()},
            {"vendor", context_.vendor()},
            {"egl_platform", context_.eglPlatform()},
            {"sync", "lock"},  // per-pixel spin-lock (imageAtomicExchange loop)
            {"GL_ARB_fragment_shader_interlock", yes(c.arbFragmentShaderInterlock)},
            {"GL_NV_fragment_shader_interlock", yes(c.nvFragmentShaderInterlock)},
            {"GL_INTEL_fragment_shader_ordering", yes(c.intelFragmentShaderOrdering)},
            {"GL_ARB_gpu_shader_int64", yes(c.arbGpuShaderInt64)},
            {"GL_NV_shader_atomic_int64", yes(c.nvShaderAtomicInt64)}};
  }

  Result<std::unique_ptr<PreparedView>> prepare(const View& view) override {
    if (!view.scene) return makeError("engine gl: a view without a scene");
    auto engine = GlEngine::create(context_, *view.scene, view.camera, view.width, view.height);
    if (!engine) return engine.error();
    return std::unique_ptr<PreparedView>(std::make_unique<GlView>(std::move(engine.value())));
  }

  Result<RenderOutput> render(const PreparedView& view, const MethodDesc& methodIn,
                              const RenderOptions& options) override {
    const auto* gv = dynamic_cast<const GlView*>(&view);
    if (!gv) return makeError("engine gl: the view was prepared by another engine");
    const PixelLayout layout{view.width(), view.height(), 0};  // row-major prefix sums on GL
    const uint64_t pixels = layout.pixels();
    MethodDesc method = methodIn;
    const bool fixedK = method.allocation == AllocationPolicy::FixedK;
    const MemoryModel memory = MemoryModel::of(method, /*fragmentParallel=*/fixedK);
    if (fixedK) {  // k from the budget (or explicit), checked as on the CPU engine
      auto a = allocate(layout, method, memory, options.budgetBytes, {}, {}, {});
      if (!a) return a.error();
      method.k = a->globalK;
    }
    GlRenderOptions go;
    go.background = options.background;
    go.readNodes = options.keepStores;
    go.warmUp = gv->firstRender();
    auto gl = gv->engine().render(method, go);
    if (!gl) return gl.error();
    GlRenderOutput& g = gl.value();
    // the A-buffer's slots are its fragments: the budget check needs the count pass's n(p)
    auto a = allocate(layout, method, memory, options.budgetBytes, g.counts, {}, {});
    if (!a) return a.error();

    RenderOutput out;
    out.image = std::move(g.image);
    RenderStats& s = out.stats;
    s.method = method.name;
    s.budgetBytes = options.budgetBytes;
    s.fragmentSlots = a->slots;
    s.bytesByCategory = memory.breakdown(pixels, a->slots);
    for (const auto& [category, bytes] : s.bytesByCategory) s.bytesUsed += bytes;
    s.bytesAllocatedByCategory = g.bufferBytes;
    s.bytesAllocated = g.totalBufferBytes();
    s.fragmentsGenerated = g.fragments;
    s.culledOccupancy = g.culledOccupancy;
    s.culledKPlus = g.culledKPlus;
    s.globalK = a->globalK;
    uint32_t kMin = UINT32_MAX, kMax = 0, maxN = 0;
    for (size_t p = 0; p < pixels; ++p) {
      const uint32_t n = g.counts[p];
      s.captured += std::min(n, a->capacity[p]);  // every store keeps the min(n, k) nearest
      if (n == 0) continue;
      ++s.coveredPixels;
      kMin = std::min(kMin, a->capacity[p]);
      kMax = std::max(kMax, a->capacity[p]);
      maxN = std::max(maxN, n);
    }
    s.kMin = s.coveredPixels ? kMin : 0;
    s.kMax = kMax;
    s.lost = s.fragmentsGenerated - s.captured;
    s.maxDepthComplexity = maxN;
    s.meanDepthComplexity =
        s.coveredPixels ? static_cast<double>(g.fragments) / s.coveredPixels : 0.0;
    s.engine = "gl";
    for (const GlPassTime& t : g.passes) {
      s.passes.push_back({t.name, t.wallMs});  // llvmpipe's GL_TIME_ELAPSED is not usable
      s.engineCounters["gpu_ms_" + t.name] = t.gpuMs;
    }
    out.kMap = std::move(a->capacity);
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

  Result<std::vector<float>> nearestCosine(const PreparedView&) override {
    return makeError(
        "--engine gl: the previous frame's |n.v| (variable k-buffer) is not in the GL engine yet");
  }

 private:
  GlContext context_;
};

}  // namespace

Result<std::unique_ptr<Engine>> makeGlEngine() {
  auto context = GlContext::create();
  if (!context) return context.error();
  return std::unique_ptr<Engine>(std::make_unique<GlRenderEngine>(std::move(context.value())));
}

void registerGlEngine() {
  registerEngine("gl", [](const EngineOptions&) { return makeGlEngine(); });
}

}  // namespace mfr::gl
