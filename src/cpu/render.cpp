// render(): the pass structure every method shares,
//   [count] -> allocate -> [depth range -> occupancy fill -> occupancy count] -> capture -> resolve
// and the statistics and memory accounting of the run.
#include "mfr/cpu/render.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <new>
#include <string>

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "mfr/core/isa.hpp"
#include "mfr/core/memory_limit.hpp"
#include "mfr/core/units.hpp"
#include "mfr/cpu/deep_importance.hpp"
#include "mfr/cpu/dkb_curve_pass.hpp"
#include "mfr/cpu/frame_buffers.hpp"
#include "mfr/cpu/optimal_oracle.hpp"
#include "mfr/learn/model_file.hpp"
#include "mfr/method/blend_support.hpp"
#include "mfr/method/optimal_allocation.hpp"
#include "mfr/method/pass_plan.hpp"
#include "pipeline.hpp"
#include "shaded_fragments.hpp"
#include "sort_nodes.hpp"

namespace mfr {
namespace {

/// The pass this thread is running (named in an out-of-memory error).
const char*& currentPass() {
  thread_local const char* pass = "set-up";
  return pass;
}

class PassTimer {
 public:
  explicit PassTimer(std::vector<PassTime>& passes) : passes_(passes) {}
  /// `name`: a static string (the out-of-memory error may name it after the pass); `recorded`:
  /// the name the statistics keep, when it differs (depth peeling's numbered passes).
  template <class Fn>
  auto run(const char* name, Fn&& fn, const std::string& recorded = {}) {
    currentPass() = name;
    const std::string& kept = recorded.empty() ? std::string(name) : recorded;
    const auto start = std::chrono::steady_clock::now();
    if constexpr (std::is_void_v<decltype(fn())>) {
      fn();
      record(kept, start);
    } else {
      auto result = fn();
      record(kept, start);
      return result;
    }
  }

 private:
  void record(const std::string& name, std::chrono::steady_clock::time_point start) {
    const std::chrono::duration<double, std::milli> d = std::chrono::steady_clock::now() - start;
    passes_.push_back({name, d.count()});
  }
  std::vector<PassTime>& passes_;
};

void buildOccupancy(const RasterFrame& frame, const Allocation& alloc, OccupancyMap& occ,
                    PassTimer& timer) {
  timer.run("depth_range", [&] {
    frame.forEachTile([&](int tile) {
      frame.rasterizeTile<ShadeMode::Coverage>(
          tile, CoverageAll{[&](uint32_t p, float z) { occ.expandRange(p, z); }});
    });
  });
  timer.run("occupancy_fill", [&] {
    frame.forEachTile([&](int tile) {
      frame.rasterizeTile<ShadeMode::Coverage>(
          tile, CoverageAll{[&](uint32_t p, float z) { occ.mark(p, z); }});
    });
  });
  timer.run("occupancy_count", [&] {
    frame.forEachTile([&](int tile) {
      const TileRect r = frame.tileRect(tile);
      for (int y = r.y0; y <= r.y1; ++y)
        for (int x = r.x0; x <= r.x1; ++x) {
          const uint32_t p = static_cast<uint32_t>(y) * frame.width() + x;
          occ.resolveThreshold(p, alloc.capacity[p]);
        }
    });
  });
}

ImageRGB resolve(const RasterFrame& frame, const MethodDesc& method, const Allocation& alloc,
                 detail::Stores& stores, glm::vec3 background) {
  if (detail::isPeerRule(method.compositing))
    return detail::resolvePeer(frame, method, alloc, stores, background);
  if (method.store == StoreChoice::LinkedList)
    return detail::resolveLinkedList(frame, method, stores, background);
  return detail::resolveSortedNodes(
      frame, method, stores, background,
      [&](size_t p, uint32_t, std::vector<FragmentNode>&) -> const FragmentNode* {
        return stores.nodes.data() + alloc.offsets[p];
      });
}

}  // namespace

std::vector<float> nearestCosine(const RasterFrame& frame) {
  std::vector<FragmentNode> nearest(frame.pixelCount(), kFarNode);
  std::vector<float> cosine(frame.pixelCount(), 0.0f);
  frame.forEachTile([&](int tile) {
    detail::forEachShadedFragment(frame, tile, [&](const Fragment& f) {
      const FragmentNode node = makeNode(f);
      if (node < nearest[f.pixel]) {
        nearest[f.pixel] = node;
        cosine[f.pixel] = std::fabs(f.ndotv);
      }
    });
  });
  // the previous-frame buffer keeps |n.v| as unorm8 (1 byte per pixel in the memory model)
  for (float& c : cosine) c = static_cast<float>(unorm8(c)) / 255.0f;
  return cosine;
}

std::vector<uint32_t> countFragments(const RasterFrame& frame) {
  std::vector<uint32_t> counts(frame.pixelCount(), 0);
  frame.forEachTile([&](int tile) {
    frame.rasterizeTile<ShadeMode::Coverage>(tile,
                                             CoverageAll{[&](uint32_t p, float) { ++counts[p]; }});
  });
  return counts;
}

namespace {

/// "abuffer at 1024 x 768 pixels", for memory errors.
std::string renderWhat(int width, int height, const MethodDesc& method) {
  return method.name + " at " + std::to_string(width) + " x " + std::to_string(height) + " pixels";
}

std::string renderWhat(const RasterFrame& frame, const MethodDesc& method) {
  return renderWhat(frame.width(), frame.height(), method);
}

/// What render() allocates per pixel before any node (docs/MEMORY.md): counters, k,
/// offsets, store kind, the output image, n(p), and the method's locks, occupancy, tail and
/// accumulators; importance allocation adds its reserved k, scratch and map. A lower bound,
/// checked before the first pass.
uint64_t perPixelBytes(const MethodDesc& method, const MemoryModel& memory) {
  uint64_t bytes = 4 + 4 + 8 + 1 + sizeof(glm::vec3);
  if (method.allocation != AllocationPolicy::FixedK) bytes += 4;
  bytes += memory.lock + memory.occupancy + memory.tail + memory.accum + memory.head;
  if (method.allocation == AllocationPolicy::Importance) bytes += 4 + 8 + 4;
  return bytes;
}

/// " and the scene's N" for a pre-flight message that counts the scene's `sceneBytes` too.
std::string besideScene(uint64_t sceneBytes) {
  return sceneBytes == 0 ? std::string() : " and the scene's " + formatBytes(sceneBytes);
}

/// checkPixelBuffers against `limit`, beside the `sceneBytes` the scene already holds.
Result<void> checkPixelBytes(int width, int height, const MethodDesc& method, CaptureMode capture,
                             uint64_t limit, uint64_t sceneBytes = 0) {
  if (width < 1 || height < 1 || width > kMaxImageSize || height > kMaxImageSize)
    return {};  // RasterFrame::build names a bad size
  const uint64_t pixels = static_cast<uint64_t>(width) * static_cast<uint64_t>(height);
  const MemoryModel memory = MemoryModel::of(method, capture == CaptureMode::FragmentParallel);
  return checkMemory(
      saturatingAdd(saturatingMul(pixels, perPixelBytes(method, memory)), sceneBytes), limit,
      renderWhat(width, height, method) + ": its per-pixel buffers" + besideScene(sceneBytes));
}

}  // namespace

Result<void> checkPixelBuffers(int width, int height, const MethodDesc& method,
                               const RenderOptions& options) {
  return checkPixelBytes(width, height, method, options.capture,
                         options.memoryLimitBytes.value_or(defaultMemoryLimit()));
}

namespace {

/// What the passes before the allocation hand to it.
struct AllocationInputs {
  ImageFeatureStats imageFeatures;  // dkb: the image's depth range, from the count pass
  std::vector<uint32_t> oracleK;    // optimal, dkb-curve: k(p) chosen before allocate
};

/// count [+ depth range]: n(p) before the allocation.
void countStep(const RasterFrame& frame, const PassPlan& plan, PassTimer& timer, RenderOutput& out,
               AllocationInputs& inputs, detail::BufferLedger& ledger) {
  if (plan.depthRange)
    out.depthComplexity =
        timer.run("count", [&] { return countWithDepthRange(frame, inputs.imageFeatures); });
  else if (plan.count)
    out.depthComplexity = timer.run("count", [&] { return countFragments(frame); });
  ledger.add("depth_complexity", out.depthComplexity);
}

/// The importance map: the deep k-buffer's network (features and inference run fused per tile;
/// the wall time is split between the two in proportion to their CPU time), or the variable
/// k-buffer's heuristic over the previous frame's nearest |n.v| (a preceding frame from the same
/// camera unless the caller hands one over).
Result<void> importanceStep(const RasterFrame& frame, const MethodDesc& method,
                            const RenderOptions& options, const PassPlan& plan,
                            const MemoryModel& memory, PassTimer& timer, RenderOutput& out,
                            const AllocationInputs& inputs, detail::BufferLedger& ledger) {
  const size_t pixels = frame.pixelCount();
  if (plan.networkImportance) {
    auto model = dkbModelFor(method);
    if (!model) return model.error();
    double featureCpu = 0.0, inferenceCpu = 0.0;
    const auto start = std::chrono::steady_clock::now();
    out.importance.importance = predictImportance(
        frame, **model, inputs.imageFeatures, memory.fragmentSlots(*options.budgetBytes, pixels),
        &featureCpu, &inferenceCpu);
    const double wall =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    const double cpu = featureCpu + inferenceCpu;
    out.stats.passes.push_back({"features", cpu > 0.0 ? wall * featureCpu / cpu : wall});
    out.stats.passes.push_back({"inference", cpu > 0.0 ? wall * inferenceCpu / cpu : 0.0});
    ledger.add("importance", out.importance.importance);
  }
  if (plan.heuristicImportance) {
    out.nearestCosine = timer.run("nearest_normal", [&] { return nearestCosine(frame); });
    const std::vector<float>& previous =
        options.previousNearestCosine && options.previousNearestCosine->size() == pixels
            ? *options.previousNearestCosine
            : out.nearestCosine;
    out.importance = timer.run("importance", [&] {
      return computeImportance(frame.width(), frame.height(), out.depthComplexity, previous,
                               method.importance);
    });
    ledger.add("nearest_normal", out.nearestCosine);
    for (const std::vector<float>* map :
         {&out.importance.importance, &out.importance.depth, &out.importance.periphery,
          &out.importance.fresnel, &out.importance.noise})
      ledger.add("importance", *map);
  }
  return {};
}

/// The optimal k-buffer's k(p) before allocate: from the exact A-buffer pre-pass's error curves
/// (the offline oracle) or from curves a network predicts (dkb-curve); both count n(p) too.
Result<void> oracleStep(const RasterFrame& frame, const MethodDesc& method,
                        const RenderOptions& options, const PassPlan& plan,
                        const MemoryModel& memory, PassTimer& timer, RenderOutput& out,
                        AllocationInputs& inputs, detail::BufferLedger& ledger) {
  if (!plan.oracle && !plan.predictedCurves) return {};
  const uint64_t slots = memory.fragmentSlots(*options.budgetBytes, frame.pixelCount());
  uint64_t prepassBytes = 0;
  if (plan.predictedCurves) {
    auto chosen = timer.run("curves", [&] { return predictedCurveK(frame, method, slots); });
    if (!chosen) return chosen.error();
    out.depthComplexity = std::move(chosen->n);
    inputs.oracleK = std::move(chosen->k);
    prepassBytes = chosen->bytesAllocated;
  } else {
    auto chosen = timer.run("oracle", [&] { return optimalK(frame, method, options, slots); });
    if (!chosen) return chosen.error();
    out.depthComplexity = std::move(chosen->n);
    inputs.oracleK = std::move(chosen->k);
    out.stats.oracle = std::move(chosen->report);
    prepassBytes = chosen->bytesAllocated;
  }
  ledger.add("depth_complexity", out.depthComplexity);
  ledger.add("oracle_k", inputs.oracleK);
  ledger.addBytes("oracle_prepass", prepassBytes);
  return {};
}

/// The node pool (a copy with keepStores), stores and image on top of what is allocated by now
/// (less what is freed: the oracle's pre-pass, the allocation's scratch) must fit the limit.
Result<void> checkNodePool(const RasterFrame& frame, const MethodDesc& method,
                           const RenderOptions& options, const MemoryModel& memory,
                           const Allocation& alloc, const detail::BufferLedger& ledger,
                           uint64_t memoryLimit) {
  const bool ownNodes =
      method.store == StoreChoice::MultiLayer || method.store == StoreChoice::LinkedList;
  const uint64_t nodeBytes =
      saturatingMul(alloc.slots, ownNodes ? memory.node : sizeof(FragmentNode));
  const uint64_t perPixel = 4 + sizeof(glm::vec3) + memory.lock + memory.occupancy + memory.tail +
                            memory.accum + memory.head;
  uint64_t held = saturatingAdd(ledger.total(), frame.sceneBytes());
  for (const char* freed : {"oracle_prepass", "allocation_scratch"})
    if (auto it = ledger.byCategory().find(freed); it != ledger.byCategory().end())
      held -= it->second;
  const uint64_t needed =
      saturatingAdd(saturatingAdd(held, saturatingMul(nodeBytes, options.keepStores ? 2 : 1)),
                    saturatingMul(frame.pixelCount(), perPixel));
  return checkMemory(needed, memoryLimit,
                     renderWhat(frame, method) + ": its " + std::to_string(alloc.slots) +
                         " fragment slots and buffers" + besideScene(frame.sceneBytes()));
}

/// `n` copies of `value` in `v`, which keeps its block (from an earlier frame, FrameBuffers) only
/// when that holds exactly n: the ledger counts capacities, as for a fresh render. n = 0 frees it.
template <class T>
void assignExact(std::vector<T>& v, size_t n, const T& value) {
  if (v.capacity() != n) std::vector<T>().swap(v);
  v.assign(n, value);
}

/// The stores the capture fills: nodes (or the peer method's buffer), counters, locks, tails.
/// `stores` may hold an earlier frame's buffers (FrameBuffers): each is sized and cleared for this
/// frame, and those this method does not use are freed.
void clearStores(const MethodDesc& method, const RenderOptions& options, const Allocation& alloc,
                 size_t pixels, detail::Stores& stores, detail::BufferLedger& ledger) {
  const bool peer = detail::isPeerRule(method.compositing);
  const bool lists = method.store == StoreChoice::LinkedList;
  stores.nodes.allocate(peer || lists ? 0 : alloc.slots);
  stores.pool.allocate(lists ? alloc.slots : 0);
  assignExact(stores.heads, lists ? pixels : 0, kListEnd);
  stores.peer = {};
  stores.peerHoldsNodes = false;
  detail::allocatePeerStores(method, alloc, pixels, stores);
  if (options.keepStores && !peer && !lists)  // unused slots are handed out: make them defined
    std::fill(stores.nodes.data(), stores.nodes.data() + alloc.slots, FragmentNode{0});
  assignExact(stores.counts, pixels, 0u);
  assignExact(stores.locks,
              options.capture == CaptureMode::FragmentParallel && !lists ? pixels : size_t{0}, 0u);
  stores.tails.allocate(method.compositing == Compositing::Hybrid || method.peelTail ? pixels : 0);
  ledger.addBytes("nodes", stores.nodes.size() * sizeof(FragmentNode));
  ledger.addBytes("nodes", stores.pool.size() * sizeof(LinkedNode));
  ledger.add("heads", stores.heads);
  ledger.add("counters", stores.counts);
  ledger.add("locks", stores.locks);
  ledger.addBytes("tail", stores.tails.bytes());
  ledger.addBytes(stores.peerHoldsNodes ? "nodes" : "accumulators", stores.peer.bytes());
}

/// Depth peeling's capture: peel passes until one takes every fragment still in range (or
/// maxPeels of them), then under peelTail the fragments left into the tails.
detail::CaptureCounters peelStep(const RasterFrame& frame, const MethodDesc& method,
                                 const RenderOptions& options, const PassPlan& plan,
                                 const Allocation& alloc, detail::Stores& stores, PassTimer& timer,
                                 RenderStats& stats) {
  detail::CaptureCounters c;
  uint32_t passes = 0;
  bool remaining = true;
  while (remaining && (!plan.maxPeels || passes < *plan.maxPeels)) {
    const detail::PeelPassCounters pc = timer.run(
        "peel",
        [&] {
          return detail::runPeelPass(frame, method, alloc, options.capture, stores,
                                     static_cast<int>(passes));
        },
        peelPassName(passes));
    if (passes == 0) c.generated = pc.generated;
    c.inserted += pc.peeled;
    ++passes;
    remaining = pc.peeled < pc.inRange;
  }
  stats.peelPasses = passes;
  if (remaining && plan.tail)
    timer.run(kPeelTailPass,
              [&] { detail::runPeelTail(frame, method, alloc, options.capture, stores); });
  return c;
}

/// The capture's counters and what only the CPU engine measures, beside fillSharedStats.
void cpuStats(const detail::CaptureCounters& counters, const detail::BufferLedger& ledger,
              RenderStats& stats) {
  stats.bytesAllocatedByCategory = ledger.byCategory();
  stats.bytesAllocated = ledger.total();
  stats.culledOccupancy = counters.culledOccupancy;
  stats.culledKPlus = counters.culledKPlus;
  stats.rejectedInStore = counters.rejected;
  stats.inserted = counters.inserted;
  stats.evicted = counters.evicted;
}

}  // namespace

static Result<RenderOutput> renderPasses(const RasterFrame& frame, const MethodDesc& method,
                                         const RenderOptions& options, uint64_t memoryLimit) {
  auto planned = planPasses(method, options);
  if (!planned) return planned.error();
  MFR_TRY(checkBlendSupport(method, frame.blendModes()));
  const PassPlan& plan = planned.value();
  RenderOutput out;
  PassTimer timer(out.stats.passes);
  detail::BufferLedger ledger;
  const size_t pixels = frame.pixelCount();
  const MemoryModel memory =
      MemoryModel::of(method, options.capture == CaptureMode::FragmentParallel);
  // memory pre-flight: the per-pixel buffers here (callers may have checked them before
  // building the frame), the node pool after allocate
  MFR_TRY(checkPixelBytes(frame.width(), frame.height(), method, options.capture, memoryLimit,
                          frame.sceneBytes()));

  // the passes before the allocation: n(p), the importance map, the oracle's k(p)
  AllocationInputs inputs;
  countStep(frame, plan, timer, out, inputs, ledger);
  MFR_TRY(importanceStep(frame, method, options, plan, memory, timer, out, inputs, ledger));
  MFR_TRY(oracleStep(frame, method, options, plan, memory, timer, out, inputs, ledger));

  // the buffers: those of the previous render when the caller keeps them (FrameBuffers; handed back
  // on every way out, errors included)
  std::unique_ptr<detail::Stores> kept = options.reuse ? options.reuse->take() : nullptr;
  struct GiveBack {
    FrameBuffers* to;
    std::unique_ptr<detail::Stores>& stores;
    ~GiveBack() {
      if (to) to->give(std::move(stores));
    }
  } giveBack{kept ? options.reuse : nullptr, kept};
  if (!kept) kept = std::make_unique<detail::Stores>();
  detail::Stores& stores = *kept;

  // allocate
  auto allocated = timer.run("allocate", [&] {
    return allocate(PixelLayout{frame.width(), frame.height(), frame.tileSize()}, method, memory,
                    options.budgetBytes, out.depthComplexity, out.importance.importance,
                    inputs.oracleK, &stores.spare);
  });
  if (!allocated) return allocated.error();
  Allocation& alloc = allocated.value();
  ledger.add("k", alloc.capacity);
  ledger.add("k", alloc.reservedK);
  ledger.add("offsets", alloc.offsets);
  ledger.add("store_kind", alloc.kind);
  ledger.addBytes("allocation_scratch", alloc.scratchBytes);
  MFR_TRY(checkNodePool(frame, method, options, memory, alloc, ledger, memoryLimit));

  // buffers
  timer.run("clear", [&] { clearStores(method, options, alloc, pixels, stores, ledger); });
  stores.maskSamples =
      frame.samples() > 1 && frame.sampleStorage() == SampleStorage::Pixel ? frame.samples() : 0;

  // occupancy culling passes
  OccupancyMap occupancy;
  if (plan.occupancy) {
    occupancy = OccupancyMap(pixels, method.occupancyWords);
    buildOccupancy(frame, alloc, occupancy, timer);
    ledger.addBytes("occupancy", occupancy.allocatedBytes());
  }

  // the peer method's own passes before its capture (mboit's moments)
  for (size_t pass = 0; pass < plan.peerPasses.size(); ++pass)
    timer.run(plan.peerPasses[pass].c_str(), [&] {
      detail::runPeerPass(frame, method, alloc, options.capture, stores, static_cast<int>(pass));
    });

  // capture
  out.stats.isa = std::string(isaName(detail::captureIsaFor(frame, method, options.capture)));
  const bool lists = method.store == StoreChoice::LinkedList;
  const detail::CaptureCounters counters =
      plan.peel
          ? peelStep(frame, method, options, plan, alloc, stores, timer, out.stats)
          : timer.run("capture", [&] {
              if (lists) return detail::captureLinkedList(frame, method, alloc, stores, ledger);
              return detail::capture(frame, method, alloc, plan.occupancy ? &occupancy : nullptr,
                                     options.capture, stores);
            });
  if (lists) alloc.capacity = stores.counts;  // k(p): the nodes each list got

  // resolve
  out.image = timer.run("resolve",
                        [&] { return resolve(frame, method, alloc, stores, options.background); });

  // statistics
  fillSharedStats(SharedMeasures{method,
                                 memory,
                                 alloc,
                                 out.depthComplexity,
                                 stores.counts,
                                 {},
                                 counters.generated,
                                 options.budgetBytes},
                  out.stats);
  cpuStats(counters, ledger, out.stats);
  out.stats.cull = frame.cull();
  out.kMap = alloc.reservedK.empty() ? std::move(alloc.capacity) : std::move(alloc.reservedK);
  out.stats.samples = frame.samples();
  out.stats.sampleStorage = frame.sampleStorage();
  if (frame.samples() > 1 && !options.keepStores)  // the engine's edge statistics read them
    out.counts = stores.counts;
  if (options.keepStores && lists) {
    detail::exportLinkedLists(stores, out);
  } else if (options.keepStores) {
    out.nodes.assign(stores.nodes.data(), stores.nodes.data() + stores.nodes.size());
    out.offsets = std::move(alloc.offsets);
    out.counts = std::move(stores.counts);
  }
  stores.spare.offsets = std::move(alloc.offsets);  // for the next frame (FrameBuffers)
  stores.spare.kind = std::move(alloc.kind);
  return out;
}

Result<RenderOutput> render(const RasterFrame& frame, const MethodDesc& method,
                            const RenderOptions& options) {
  const uint64_t limit = options.memoryLimitBytes.value_or(defaultMemoryLimit());
  struct RestorePass {  // a nested render (the oracle's pre-pass) leaves the outer pass named
    const char* outer = currentPass();
    ~RestorePass() { currentPass() = outer; }
  } restore;
  currentPass() = "set-up";
  try {
    return renderPasses(frame, method, options, limit);
  } catch (const std::bad_alloc&) {  // the pre-flight let it through, the allocation failed anyway
    return makeError(renderWhat(frame, method) + ": out of memory allocating the buffers of the " +
                     currentPass() + " pass (memory limit " + formatBytes(limit) +
                     "; --memory-limit)");
  }
}

}  // namespace mfr
