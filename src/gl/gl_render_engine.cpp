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
#include "mfr/gl/gl_technique.hpp"
#include "mfr/learn/model_file.hpp"
#include "mfr/method/allocation.hpp"
#include "mfr/method/blend_support.hpp"
#include "mfr/method/dkb_model.hpp"
#include "mfr/method/importance.hpp"
#include "mfr/method/memory_model.hpp"
#include "mfr/method/optimal_allocation.hpp"
#include "mfr/method/pass_plan.hpp"

namespace mfr::gl {
namespace {

class GlView final : public PreparedView {
 public:
  GlView(GlEngine engine, const View& view, const GlContext& context, bool interlock)
      : engine_(std::move(engine)), view_(view), context_(&context), interlock_(interlock) {}
  // the view's GL objects are deleted in its own context, whichever another GL engine on this
  // thread made current since (the view must not outlive its engine)
  ~GlView() override { context_->makeCurrent(); }
  GlView(const GlView&) = delete;
  GlView& operator=(const GlView&) = delete;
  int width() const override { return view_.width; }
  int height() const override { return view_.height; }
  int samples() const override { return view_.samples; }
  /// The engine of a storage discipline: the view's own (one sample, or per-pixel storage with
  /// coverage masks), or, multisampled with per-sample storage, a second one made on first use.
  Result<GlEngine*> engine(SampleStorage storage) const {
    if (view_.samples == 1 || storage == SampleStorage::Pixel) return &engine_;
    if (!sampleEngine_) {
      auto made = GlEngine::create(*context_, *view_.scene, view_.camera, view_.width, view_.height,
                                   interlock_, engine_.raster(),
                                   GlSampling{view_.samples, SampleStorage::Sample});
      if (!made) return made.error();
      sampleEngine_ = std::make_unique<GlEngine>(std::move(made.value()));
    }
    return sampleEngine_.get();
  }
  GlEngine& engine() const { return engine_; }
  /// Multisampled: the pixels an edge crosses (the per-pixel engine's coverage), once per view.
  Result<const std::vector<uint8_t>*> edgePixels() const {
    if (edges_.empty()) {
      auto edges = engine_.edgePixels();
      if (!edges) return edges.error();
      edges_ = std::move(edges.value());
    }
    return &edges_;
  }
  const View& view() const { return view_; }  // for the CPU oracle of the optimal k-buffer
  /// True the first time: the first render of a view warms up (shader compilation, llvmpipe's
  /// first-frame timer values), later ones are timed as they run.
  bool firstRender() const { return std::exchange(first_, false); }

 private:
  mutable GlEngine engine_;  // rendering changes GL state, not the view
  mutable std::unique_ptr<GlEngine> sampleEngine_;
  mutable std::vector<uint8_t> edges_;
  View view_;
  const GlContext* context_;
  bool interlock_ = false;
  mutable bool first_ = true;
};

double msSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// The CPU engine's frame of the view, for the passes the GL engine leaves to the host: the
// view's samples, in the method's storage discipline.
Result<RasterFrame> cpuFrameOf(const View& view, const MethodDesc& method,
                               const RenderOptions& options) {
  RasterOptions ro;
  ro.width = view.width;
  ro.height = view.height;
  ro.samples = view.samples;
  ro.storage = sampleStorageOf(method, options);
  return RasterFrame::build(*view.scene, view.camera, ro);
}

// The optimal k-buffer's k(p) from the CPU engine's oracle (optimalK, mfr/cpu/optimal_oracle.hpp)
// on the same view.
Result<OracleChoice> cpuOracle(const View& view, const MethodDesc& method,
                               const RenderOptions& options, uint64_t slots) {
  auto frame = cpuFrameOf(view, method, options);
  if (!frame) return frame.error();
  return optimalK(*frame, method, options, slots);
}

// dkb-curve's n(p) and k(p) from the CPU engine's passes (predictedCurveK,
// mfr/cpu/dkb_curve_pass.hpp) on the same view.
Result<CurveChoice> cpuCurves(const View& view, const MethodDesc& method,
                              const RenderOptions& options, uint64_t slots) {
  auto frame = cpuFrameOf(view, method, options);
  if (!frame) return frame.error();
  return predictedCurveK(*frame, method, slots);
}

// The GL k-buffers take the per-pixel spin-lock: the CPU engine's fragment-parallel memory
// (wboit's accumulators too); the A-buffer appends with atomics.
MemoryModel glMemoryModel(const MethodDesc& method) {
  return MemoryModel::of(method, method.allocation != AllocationPolicy::Unbounded);
}

// One render on the GL engine, in the pass plan's steps: the allocation (in compute shaders, or
// on the host from n(p) and the importance map or the CPU oracle's k(p)), the GL capture and
// resolve, the statistics.
class GlFrame {
 public:
  GlFrame(const GlView& view, GlEngine& engine, const MethodDesc& method, const PassPlan& plan,
          const RenderOptions& options)
      : gv_(view),
        engine_(engine),
        method_(method),
        plan_(plan),
        options_(options),
        layout_{engine.width(), engine.height(), 0},  // row-major prefix sums on GL; storage
        memory_(glMemoryModel(method)) {}

  /// Counted, dynamic and importance-map k: count, histogram, importance, k(p), prefix sum in
  /// compute shaders; the host reads a few totals and checks them with allocate()'s words.
  bool onDevice() const {
    const AllocationPolicy a = method_.allocation;
    return a == AllocationPolicy::CountedK || a == AllocationPolicy::DynamicK ||
           (a == AllocationPolicy::Importance &&
            method_.importanceSource != ImportanceSource::Network && !method_.fillUnusedSlots);
  }
  /// Variable k the host allocates: n(p) [and I(p) or the oracle's k(p)] measured first, k(p)
  /// and offsets from the shared allocate(), then the GL capture and resolve with them.
  bool onHost() const {
    const AllocationPolicy a = method_.allocation;
    return !onDevice() && (a == AllocationPolicy::CountedK || a == AllocationPolicy::DynamicK ||
                           a == AllocationPolicy::Importance || a == AllocationPolicy::Optimal);
  }

  Result<RenderOutput> run(bool interlock) {
    auto technique = classifyGl(method_);  // before any pass: a method the GL engine lacks
    if (!technique) return technique.error();
    if (method_.allocation == AllocationPolicy::FixedK) {  // k from the budget, as on the CPU
      auto a = allocate(layout_, method_, memory_, options_.budgetBytes, {}, {}, {});
      if (!a) return a.error();
      method_.k = a->globalK;
    }
    uint64_t poolNodes = 0;
    if (method_.allocation == AllocationPolicy::Pool) {  // the pool: F(M), or every fragment
      if (!options_.budgetBytes) {
        MFR_TRY(budgetSlots(layout_, method_, memory_, options_.budgetBytes));
        auto counted = engine_.count();
        if (!counted) return counted.error();
        n_ = std::move(counted.value());
      }
      auto a = allocate(layout_, method_, memory_, options_.budgetBytes, n_, {}, {});
      if (!a) return a.error();
      poolNodes = a->slots;
    }
    std::optional<uint32_t> deviceGlobalK;
    std::optional<Allocation> perPixel;
    if (onDevice()) {
      auto k = allocateOnDevice();
      if (!k) return k.error();
      deviceGlobalK = k.value();
    } else if (onHost()) {
      auto a = allocateOnHost();
      if (!a) return a.error();
      perPixel = std::move(a.value());
    }
    GlRenderOptions go;
    go.background = options_.background;
    go.readNodes = options_.keepStores;
    go.warmUp = gv_.firstRender();
    go.allocation = perPixel ? &*perPixel : nullptr;
    go.deviceAllocation = onDevice();
    go.poolNodes = poolNodes;
    // (GL's own n(p) only: the optimal k-buffer's and dkb-curve's come from CPU passes)
    go.counts = n_.empty() || method_.allocation == AllocationPolicy::Optimal ? nullptr : &n_;
    auto gl = engine_.render(method_, go);
    if (!gl) return gl.error();
    GlRenderOutput& g = gl.value();
    // the A-buffer's slots are its fragments: the budget check needs the count pass's n(p)
    auto a = onDevice() ? engine_.readDeviceAllocation()
             : perPixel
                 ? Result<Allocation>(std::move(*perPixel))
                 : allocate(layout_, method_, memory_, options_.budgetBytes, g.counts, {}, {});
    if (!a) return a.error();
    if (onDevice()) {
      a->globalK = deviceGlobalK;
      MFR_TRY(readDeviceMaps());
    }
    // linked lists: k(p), the nodes each list got (depth peeling's held are fragments, not k)
    if (method_.store == StoreChoice::LinkedList && !g.held.empty()) a->capacity = g.held;
    fillStats(g, a.value(), interlock);
    const GlSampling& sampling = engine_.sampling();
    if (sampling.samples > 1) {
      auto edges = gv_.edgePixels();
      if (!edges) return edges.error();
      edgeStatistics(g.counts, capturedPerPixel(*technique, g, a.value()), **edges,
                     sampling.storagePerPixel(), out_);
    }
    out_.image = std::move(g.image);
    out_.kMap = a->reservedK.empty() ? std::move(a->capacity) : std::move(a->reservedK);
    out_.depthComplexity = std::move(g.counts);
    if (options_.keepStores) {
      out_.nodes = std::move(g.nodes);
      out_.offsets = std::move(g.nodeOffsets);
      out_.counts = std::move(g.nodeCounts);
    }
    if (sampling.storagePerPixel() > 1)  // the W S x H storage to the W x H image
      toImagePixels(out_, sampling.storagePerPixel());
    return std::move(out_);
  }

 private:
  /// The nodes each storage pixel kept of its n(p) fragments, as the CPU engine's stores count
  /// them (edgeStatistics takes min(n(p), this)); empty: every fragment (the accumulating peers).
  std::vector<uint32_t> capturedPerPixel(GlTechnique technique, const GlRenderOutput& g,
                                         const Allocation& a) const {
    switch (technique) {
      case GlTechnique::ABuffer:
      case GlTechnique::Wboit:
      case GlTechnique::Mboit:
      case GlTechnique::Aoit:
      case GlTechnique::Dfaoit:
      case GlTechnique::Stochastic:
      case GlTechnique::HashedAlpha:
        return {};
      case GlTechnique::KBuffer:
      case GlTechnique::Mlab:
        if (a.capacity.size() == layout_.pixels()) return a.capacity;
        return std::vector<uint32_t>(layout_.pixels(), method_.k.value_or(0));
      case GlTechnique::LinkedList:
      case GlTechnique::Peel:
        return g.held;
    }
    return {};
  }

  uint64_t slots() const { return memory_.fragmentSlots(*options_.budgetBytes, layout_.pixels()); }

  const std::vector<float>& previousCosine(const std::vector<float>& otherwise) {
    const std::vector<float>* previous = options_.previousNearestCosine;
    if (!previous) return otherwise;
    if (previous->size() == layout_.pixels()) return *previous;
    // per-sample storage: the previous image's |n.v| for each of its pixel's samples
    const uint64_t per = previous->empty() ? 0 : layout_.pixels() / previous->size();
    if (per < 2 || previous->size() * per != layout_.pixels()) return otherwise;
    expandedCosine_.clear();
    expandedCosine_.reserve(layout_.pixels());
    for (float c : *previous) expandedCosine_.insert(expandedCosine_.end(), per, c);
    return expandedCosine_;
  }

  /// The device allocation; the global k of a counted or dynamic k.
  Result<std::optional<uint32_t>> allocateOnDevice() {
    MFR_TRY(budgetSlots(layout_, method_, memory_, options_.budgetBytes));  // before any pass
    std::vector<GlPassTime> passes;
    auto summary = engine_.countOnDevice(&passes);
    if (!summary) return summary.error();
    std::optional<uint32_t> globalK;
    if (method_.allocation == AllocationPolicy::Importance) {
      MFR_TRY(
          checkCoveredPixels(layout_, method_, memory_, options_.budgetBytes, summary->covered));
      static const std::vector<float> none;
      auto totals = engine_.allocateByImportance(method_.importance, previousCosine(none), slots(),
                                                 method_.store, &passes);
      if (!totals) return totals.error();
      // floor(P(p) F(M)) sums to at most F(M) with IEEE double arithmetic (as on the host);
      // a driver whose double division rounds otherwise could exceed it by a few slots
      if (totals->reservedSlots > slots())
        return makeError("--engine gl: " + method_.name +
                         ": the GPU's importance allocation took " +
                         std::to_string(totals->reservedSlots) + " slots of " +
                         std::to_string(slots()) + " (double arithmetic not IEEE on this driver)");
    } else {
      auto k = boundedK(layout_, method_, memory_, options_.budgetBytes, *summary);
      if (!k) return k.error();
      auto totals = engine_.allocateCapped(*k, method_.store, &passes);
      if (!totals) return totals.error();
      MFR_TRY(
          checkBoundedSlots(layout_, method_, memory_, options_.budgetBytes, *k, totals->slots));
      globalK = *k;
    }
    for (const GlPassTime& t : passes) hostPasses_.push_back({t.name + " (allocation)", t.wallMs});
    return globalK;
  }

  /// The host allocation: n(p) (the count pass, or the CPU oracle's or curves' pre-pass), the
  /// importance map, then the shared allocate().
  Result<Allocation> allocateOnHost() {
    std::vector<uint32_t> oracleK;
    auto t0 = std::chrono::steady_clock::now();
    if (plan_.predictedCurves) {  // dkb-curve: features, network and hull on the host
      auto chosen = cpuCurves(gv_.view(), method_, options_, slots());
      if (!chosen) return chosen.error();
      n_ = std::move(chosen->n);
      oracleK = std::move(chosen->k);
      hostPasses_.push_back({"curves (cpu)", msSince(t0)});
    } else if (plan_.oracle) {
      auto chosen = cpuOracle(gv_.view(), method_, options_, slots());
      if (!chosen) return chosen.error();
      n_ = std::move(chosen->n);
      oracleK = std::move(chosen->k);
      out_.stats.oracle = std::move(chosen->report);
      hostPasses_.push_back({"oracle (cpu)", msSince(t0)});
    } else {
      auto counted = engine_.count();
      if (!counted) return counted.error();
      n_ = std::move(counted.value());
      hostPasses_.push_back({"count (n(p) read back)", msSince(t0)});
    }
    if (plan_.networkImportance) MFR_TRY(networkImportance());
    if (plan_.heuristicImportance) MFR_TRY(heuristicImportance());
    t0 = std::chrono::steady_clock::now();
    auto a = allocate(layout_, method_, memory_, options_.budgetBytes, n_,
                      out_.importance.importance, oracleK);
    hostPasses_.push_back({"allocate (host)", msSince(t0)});
    return a;
  }

  /// The deep k-buffer: features and network on GL (dkb_infer.comp).
  Result<void> networkImportance() {
    auto model = dkbModelFor(method_);
    if (!model) return model.error();
    const learn::Mlp& net = (*model)->net;
    if (net.sizes != learn::kDkbLayers)
      return makeError("--engine gl: " + method_.name +
                       ": the GL engine runs 12-128-64-1 networks only");
    std::vector<float> weights;
    for (size_t l = 0; l < net.weights.size(); ++l) {
      const auto& w = net.weights[l];
      const auto& b = net.biases[l];
      weights.insert(weights.end(), w.data(), w.data() + w.size());  // column-major
      weights.insert(weights.end(), b.data(), b.data() + b.size());
    }
    std::vector<GlPassTime> passes;
    auto importance = engine_.dkbImportance(weights, slots(), &passes);
    if (!importance) return importance.error();
    out_.importance.importance = std::move(importance.value());
    for (const GlPassTime& t : passes) hostPasses_.push_back({t.name, t.wallMs});
    return {};
  }

  /// The variable k-buffer: the nearest |n.v| on GL, the map on the host.
  Result<void> heuristicImportance() {
    auto t0 = std::chrono::steady_clock::now();
    auto cosine = engine_.nearestCosine();
    if (!cosine) return cosine.error();
    out_.nearestCosine = std::move(cosine.value());
    hostPasses_.push_back({"nearest_normal", msSince(t0)});
    t0 = std::chrono::steady_clock::now();
    out_.importance = computeImportance(layout_.width, layout_.height, n_,
                                        previousCosine(out_.nearestCosine), method_.importance);
    hostPasses_.push_back({"importance (host)", msSince(t0)});
    return {};
  }

  /// The device allocation's importance maps, read back for the output.
  Result<void> readDeviceMaps() {
    if (method_.allocation != AllocationPolicy::Importance) return {};
    auto maps = engine_.readImportance();
    if (!maps) return maps.error();
    out_.importance = std::move(maps.value());
    auto cosine = engine_.readNearestCosine();
    if (!cosine) return cosine.error();
    out_.nearestCosine = std::move(cosine.value());
    return {};
  }

  void fillStats(const GlRenderOutput& g, const Allocation& a, bool interlock) {
    RenderStats& s = out_.stats;
    // the plan's n(p) (a count pass, the oracle's pre-pass) as the CPU engine reports it; the
    // stores hold min(n(p), k(p)) of the n(p) the capture counted
    const bool counted = plan_.count || plan_.oracle || plan_.predictedCurves;
    static const std::vector<uint32_t> none;
    // (depth peeling holds the fragments it peeled, counted per pixel by peel_step.comp)
    fillSharedStats(
        SharedMeasures{method_, memory_, a, counted ? g.counts : none, g.held,
                       g.held.empty() ? g.counts : none, g.fragments, options_.budgetBytes},
        s);
    s.peelPasses = g.peelPasses;
    s.bytesAllocatedByCategory = g.bufferBytes;
    s.bytesAllocated = g.totalBufferBytes();
    s.culledOccupancy = g.culledOccupancy;
    s.culledKPlus = g.culledKPlus;
    s.engine = "gl";
    s.cull = gv_.view().scene->cull;
    s.samples = engine_.sampling().samples;
    s.sampleStorage = engine_.sampling().storage;
    s.passes = std::move(hostPasses_);  // the host side of a variable-k allocation first
    for (const GlPassTime& t : g.passes) {
      s.passes.push_back({t.name, t.wallMs});  // llvmpipe's GL_TIME_ELAPSED is not usable
      s.engineCounters["gpu_ms_" + t.name] = t.gpuMs;
    }
    s.engineCounters["sync_interlock"] = interlock ? 1 : 0;  // the k-buffer capture's sync
    // the geometry passes: 1 GL's own pipeline (--gl-raster native), 0 the emulated (exact)
    s.engineCounters["raster_native"] = engine_.raster() == GlRaster::Native ? 1 : 0;
    // the fixed-k capture with 64-bit atomicMin instead of the lock (where the driver has them)
    s.engineCounters["atomic64"] = g.atomic64 ? 1 : 0;
  }

  const GlView& gv_;
  GlEngine& engine_;  // the view's engine of the method's storage discipline
  MethodDesc method_;
  const PassPlan& plan_;
  const RenderOptions& options_;
  const PixelLayout layout_;
  const MemoryModel memory_;
  std::vector<PassTime> hostPasses_;
  std::vector<uint32_t> n_;            // host allocation: n(p) measured first, reused by the frame
  std::vector<float> expandedCosine_;  // per-sample storage: the previous |n.v| per sample
  RenderOutput out_;
};

class GlRenderEngine final : public Engine {
 public:
  GlRenderEngine(GlContext context, bool interlock, GlRaster raster)
      : context_(std::move(context)), interlock_(interlock), raster_(raster) {}

  std::string_view name() const override { return "gl"; }

  std::map<std::string, std::string> describe() const override {
    const GlExtensions& c = context_.extensions();
    const auto yes = [](bool b) { return std::string(b ? "yes" : "no"); };
    return {{"engine", "gl"},
            {"renderer", context_.renderer()},
            {"version", context_.version()},
            {"vendor", context_.vendor()},
            {"egl_platform", context_.eglPlatform()},
            // the geometry passes: GL's own pipeline or the CPU engine's emulated (--gl-raster)
            {"raster", toString(raster_)},
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

  MemoryModel memoryModel(const MethodDesc& method, const RenderOptions&) const override {
    return glMemoryModel(method);
  }

  Result<std::unique_ptr<PreparedView>> prepare(const View& view) override {
    if (!view.scene) return makeError("--engine gl: a view without a scene");
    // (multisampled: the engine of per-pixel storage; GlView makes per-sample storage's on use)
    auto engine = GlEngine::create(context_, *view.scene, view.camera, view.width, view.height,
                                   interlock_, raster_, GlSampling{view.samples});
    if (!engine) return engine.error();
    return std::unique_ptr<PreparedView>(
        std::make_unique<GlView>(std::move(engine.value()), view, context_, interlock_));
  }

  Result<RenderOutput> render(const PreparedView& view, const MethodDesc& method,
                              const RenderOptions& options) override {
    auto glv = glView(view);
    if (!glv) return glv.error();
    const GlView* gv = *glv;
    auto plan = planPasses(method, options);
    if (!plan) return plan.error();
    MFR_TRY(checkBlendSupport(method, gv->view().scene->blendModes()));
    auto engine = gv->engine(sampleStorageOf(method, options));
    if (!engine) return engine.error();
    return GlFrame(*gv, **engine, method, plan.value(), options).run(interlock_);
  }

  Result<std::vector<uint32_t>> countFragments(const PreparedView& view) override {
    // the count pass alone (no A-buffer, which need not fit a storage block); multisampled, per
    // sample, summed per pixel (the per-sample A-buffer's nodes, as the CPU engine counts)
    auto gv = glView(view);
    if (!gv) return gv.error();
    auto engine = (*gv)->engine(SampleStorage::Sample);
    if (!engine) return engine.error();
    auto counted = (*engine)->count();
    if (!counted) return counted.error();
    RenderOutput out;
    out.depthComplexity = std::move(counted.value());
    toImagePixels(out, (*engine)->sampling().storagePerPixel());
    return std::move(out.depthComplexity);
  }

  Result<std::vector<float>> nearestCosine(const PreparedView& view) override {
    auto gv = glView(view);
    if (!gv) return gv.error();
    return (*gv)->engine().nearestCosine();
  }

 private:
  // a view this engine prepared, its context made current (another GL engine on this thread may
  // have made its own current)
  Result<const GlView*> glView(const PreparedView& view) const {
    const auto* gv = dynamic_cast<const GlView*>(&view);
    if (!gv) return makeError("--engine gl: the view was prepared by another engine");
    context_.makeCurrent();
    return gv;
  }

  GlContext context_;
  bool interlock_ = false;
  GlRaster raster_ = GlRaster::Native;
};

}  // namespace

Result<std::unique_ptr<Engine>> makeGlEngine(const std::string& sync, const std::string& raster) {
  if (sync != "auto" && sync != "lock" && sync != "interlock")
    return makeError("--gl-sync '" + sync + "': expected auto, lock or interlock");
  auto rasterMode = parseGlRaster(raster);
  if (!rasterMode) return rasterMode.error();
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
      std::make_unique<GlRenderEngine>(std::move(context.value()), interlock, *rasterMode));
}

void registerGlEngine() {
  registerEngine("gl", [](const EngineOptions& o) { return makeGlEngine(o.glSync, o.glRaster); });
}

}  // namespace mfr::gl
