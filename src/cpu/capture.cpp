// The capture pass (k+-buffer paper, Algorithm 3 STORE; occupancy paper sec. 2 for the early test).
//
// Per fragment, in order:
//   1. occupancy test: a fragment in a bucket beyond the pixel's k-th occupied one is rejected;
//   2. k+ test, outside the critical section: a full store rejects a fragment that is not nearer
//      than its maximum (slot 0);
//   3. critical section: insert into the max-array / max-heap / append store, which tests again
//      (another fragment may have filled the store or lowered its maximum meanwhile).
// With kbuffer compositing, tests 1 and 2 run before shading (like early-z). With hybrid
// compositing every fragment is shaded, and the rejected and evicted ones are added to the
// pixel's tail.
//
// Tile-owned mode: a tile is one worker's, fragments reach a pixel in primitive order, no locks.
// Fragment-parallel mode: triangles are rasterized whole by any thread in any interleaving; each
// pixel's critical section is guarded by a spin-lock taken with an atomic exchange (the paper's
// semaphore); slot 0 and the counter, read by test 2 outside the lock, are relaxed atomics. On a
// CPU the spinning thread yields instead of giving up after a number of iterations (the GPU code
// drops the fragment after 1000 tries; a CPU thread cannot deadlock a SIMT group here), so no
// fragment is ever dropped.
#include <atomic>
#include <thread>

#include <algorithm>

#include "max_heap_replace.hpp"
#include "mfr/core/isa.hpp"
#include "pipeline.hpp"
#include "raster_span_avx2.hpp"

namespace mfr::detail {
namespace {

struct SpinLock {
  static void lock(Stores& stores, uint32_t p) {
    std::atomic_ref<uint32_t> a(stores.locks[p]);
    int spins = 0;
    while (a.exchange(1, std::memory_order_acquire) != 0) {
      while (a.load(std::memory_order_relaxed) != 0) {
        if (++spins > 64) std::this_thread::yield();
      }
    }
  }
  static void unlock(Stores& stores, uint32_t p) {
    std::atomic_ref<uint32_t>(stores.locks[p]).store(0, std::memory_order_release);
  }
};

struct NoLock {
  static void lock(Stores&, uint32_t) {}
  static void unlock(Stores&, uint32_t) {}
};

template <bool Hybrid, bool Occupancy, bool KPlus, class Access, class Lock>
struct CaptureSink {
  const Allocation& alloc;
  const OccupancyMap* occupancy;
  Stores& stores;
  CaptureCounters counters;

  FragmentNode* slots(uint32_t p) { return stores.nodes.data() + alloc.offsets[p]; }

  // early test before shading (kbuffer compositing only: hybrid needs every fragment's colour)
  bool accept(uint32_t p, float depth) {
    ++counters.generated;
    if constexpr (!Hybrid) {
      if (Occupancy && occupancy->culls(p, depth)) {
        ++counters.culledOccupancy;
        return false;
      }
      // conservative: colour 0 is the smallest tie-break, so a reject here is a reject for any
      if (KPlus && !passesKPlusTest<Access>(slots(p), stores.counts[p], alloc.capacity[p],
                                            makeNode(depth, 0u))) {
        ++counters.culledKPlus;
        return false;
      }
    }
    return true;
  }

  void toTail(uint32_t p, FragmentNode node) {
    if constexpr (Hybrid) stores.toTail(p, node);
  }

  void emit(const Fragment& f) {
    const uint32_t p = f.pixel;
    const FragmentNode node = makeNode(f);
    if constexpr (Hybrid && Occupancy) {
      if (occupancy->culls(p, f.depth)) {
        ++counters.culledOccupancy;
        Lock::lock(stores, p);
        toTail(p, node);
        Lock::unlock(stores, p);
        return;
      }
    }
    FragmentNode* s = slots(p);
    if constexpr (KPlus) {
      if (!passesKPlusTest<Access>(s, stores.counts[p], alloc.capacity[p], node)) {
        ++counters.culledKPlus;
        if constexpr (Hybrid) {
          Lock::lock(stores, p);
          toTail(p, node);
          Lock::unlock(stores, p);
        }
        return;
      }
    }
    Lock::lock(stores, p);
    FragmentNode evicted = 0;
    switch (
        storeInsert<Access>(alloc.kind[p], s, stores.counts[p], alloc.capacity[p], node, evicted)) {
      case InsertOutcome::Inserted:
        ++counters.inserted;
        break;
      case InsertOutcome::Replaced:
        ++counters.inserted;
        ++counters.evicted;
        toTail(p, evicted);
        break;
      case InsertOutcome::Rejected:
        ++counters.rejected;
        toTail(p, node);
        break;
    }
    Lock::unlock(stores, p);
  }
};

#if MFR_HAS_AVX2_KERNELS
/// The lane protocol of RasterFrame::rasterizeTileAvx2 over the tile-owned kbuffer sink: the
/// tile's cull depths (raster_span_avx2.hpp), refreshed after every insertion; the insertion
/// itself and its counters are the scalar sink's.
template <bool Occupancy, bool KPlus>
struct LaneCaptureSink {
  using Inner = CaptureSink<false, Occupancy, KPlus, PlainAccess, NoLock>;
  static constexpr bool kCullsInLanes = Occupancy;  // occupancy is tested before k+, per lane

  Inner inner;
  int width = 0;
  TileRect tile{};
  int stride = 0;
  std::vector<int32_t> cullDepth;  // the tile's pixels, row stride = tile size

  int32_t* cullDepthRow(int localY) { return cullDepth.data() + localY * stride; }

  int32_t cullDepthOf(uint32_t p) {
    if constexpr (!KPlus) return INT32_MAX;
    return detail::cullDepthOf(inner.slots(p), inner.stores.counts[p], inner.alloc.capacity[p]);
  }

  void beginTile(const TileRect& r, int tileSize) {
    tile = r;
    stride = tileSize;
    cullDepth.resize(static_cast<size_t>(tileSize) * tileSize);
    for (int y = r.y0; y <= r.y1; ++y)
      for (int x = r.x0; x <= r.x1; ++x)
        cullDepthRow(y - r.y0)[x - r.x0] = cullDepthOf(static_cast<uint32_t>(y) * width + x);
  }

  // the lanes of an 8-pixel step: all passed the alpha test; `culled` failed the k+ test
  void countEarly(uint32_t generated, uint32_t culled) {
    inner.counters.generated += generated;
    inner.counters.culledKPlus += culled;
  }
  [[gnu::always_inline]] bool acceptLane(uint32_t p, float depth, bool passesKPlus) {
    ++inner.counters.generated;
    if (Occupancy && inner.occupancy->culls(p, depth)) {
      ++inner.counters.culledOccupancy;
      return false;
    }
    if (!passesKPlus) {
      ++inner.counters.culledKPlus;
      return false;
    }
    return true;
  }
  // inlined into the (AVX2) lane kernel: a call to this baseline code would run its SSE
  // instructions with the kernel's upper register halves dirty
  [[gnu::always_inline]] void emitLane(const Fragment& f, int32_t* cull) {
    if constexpr (KPlus) {
      // a full max-heap: the k+ test and the root replacement without branches on the data
      // (max_heap_replace.hpp); everything else through the scalar sink
      const uint32_t p = f.pixel;
      const uint32_t n = inner.stores.counts[p];
      if (inner.alloc.kind[p] == StoreKind::MaxHeap && n > 0 && n == inner.alloc.capacity[p]) {
        FragmentNode* s = inner.slots(p);
        const FragmentNode node = makeNode(f);
        if (!(node < s[0])) {
          ++inner.counters.culledKPlus;
          return;
        }
        maxHeapReplaceRoot(s, n, node);
        ++inner.counters.inserted;
        ++inner.counters.evicted;
        *cull = cullDepthOf(p);
        return;
      }
    }
    inner.emit(f);
    if constexpr (KPlus) *cull = cullDepthOf(f.pixel);
  }

  // the scalar protocol, for the triangles the lanes do not take (textured, alpha-masked)
  bool accept(uint32_t p, float depth) { return inner.accept(p, depth); }
  // (such a tile is all scalar: its cull depths are never read, nor filled by beginTile)
  void emit(const Fragment& f) {
    int32_t unread;
    emitLane(f, &unread);
  }
};

/// The lane protocol over the tile-owned hybrid sink: hybrid compositing shades every fragment
/// (the rejected ones feed the tail), so no lane is culled before shading (every cull depth is
/// INT32_MAX) and each shaded lane goes through the scalar sink's tests, insertion and tail.
template <bool Occupancy, bool KPlus>
struct LaneHybridSink {
  using Inner = CaptureSink<true, Occupancy, KPlus, PlainAccess, NoLock>;
  static constexpr bool kCullsInLanes = false;

  Inner inner;
  std::vector<int32_t> noCull;  // one row of INT32_MAX, shared by every row

  void beginTile(const TileRect&, int tileSize) { noCull.assign(tileSize, INT32_MAX); }
  int32_t* cullDepthRow(int) { return noCull.data(); }
  void countEarly(uint32_t generated, uint32_t) { inner.counters.generated += generated; }
  [[gnu::always_inline]] void emitLane(const Fragment& f, int32_t*) { inner.emit(f); }
  // the scalar protocol, for the tiles the lanes do not take (textured, alpha-masked)
  bool accept(uint32_t p, float depth) { return inner.accept(p, depth); }
  void emit(const Fragment& f) { inner.emit(f); }
};
#endif

/// The instruction set the capture of this method runs on: the 8-lane kernel serves the
/// tile-owned captures (fragment-parallel capture has no tiles).
Isa captureIsa(const MethodDesc& method, CaptureMode mode) {
#if MFR_HAS_AVX2_KERNELS
  if (mode == CaptureMode::TileOwned && activeIsa() >= Isa::Avx2) return Isa::Avx2;
#endif
  (void)method;
  (void)mode;
  return Isa::Scalar;
}

template <bool Hybrid, bool Occupancy, bool KPlus>
CaptureCounters runCapture(const RasterFrame& frame, const Allocation& alloc,
                           const OccupancyMap* occupancy, CaptureMode mode, Isa isa,
                           Stores& stores) {
  CaptureCounters total;
#if MFR_HAS_AVX2_KERNELS
  if (isa == Isa::Avx2) {
    const ShadingInputs inputs = frame.shadingInputs();
    std::vector<CaptureCounters> perTile(static_cast<size_t>(frame.tileCount()));
    frame.forEachTile([&](int tile) {
      // a tile no triangle reaches has nothing to capture: skip its per-pixel cull depths
      if (frame.tileBegin(tile) == frame.tileEnd(tile)) return;
      thread_local std::vector<int32_t> cullDepth;  // reused by the worker's tiles
      if constexpr (Hybrid) {
        LaneHybridSink<Occupancy, KPlus> sink{{alloc, occupancy, stores, {}}, std::move(cullDepth)};
        rasterizeTileAvx2(frame, inputs, tile, sink);
        perTile[tile] = sink.inner.counters;
        cullDepth = std::move(sink.noCull);
      } else {
        LaneCaptureSink<Occupancy, KPlus> sink{
            {alloc, occupancy, stores, {}}, frame.width(), {}, 0, std::move(cullDepth)};
        rasterizeTileAvx2(frame, inputs, tile, sink);
        perTile[tile] = sink.inner.counters;
        cullDepth = std::move(sink.cullDepth);
      }
    });
    for (const CaptureCounters& c : perTile) total.add(c);
    return total;
  }
#endif
  if (mode == CaptureMode::TileOwned) {
    std::vector<CaptureCounters> perTile(static_cast<size_t>(frame.tileCount()));
    frame.forEachTile([&](int tile) {
      CaptureSink<Hybrid, Occupancy, KPlus, PlainAccess, NoLock> sink{alloc, occupancy, stores, {}};
      frame.rasterizeTile<ShadeMode::Full>(tile, sink);
      perTile[tile] = sink.counters;
    });
    for (const CaptureCounters& c : perTile) total.add(c);
    return total;
  }
  // plain std::threads (not the TBB pool) pulling chunks of triangles from a shared cursor: any
  // interleaving of fragments across pixels, and a pass ThreadSanitizer can follow end to end
  using Sink = CaptureSink<Hybrid, Occupancy, KPlus, AtomicAccess, SpinLock>;
  const size_t triangles = frame.setups().size();
  constexpr size_t kChunk = 16;
  std::atomic<size_t> cursor{0};
  std::vector<CaptureCounters> perThread(static_cast<size_t>(frame.threads()));
  std::vector<std::thread> workers;
  for (int w = 0; w < frame.threads(); ++w)
    workers.emplace_back([&, w] {
      Sink sink{alloc, occupancy, stores, {}};
      for (size_t begin = cursor.fetch_add(kChunk); begin < triangles;
           begin = cursor.fetch_add(kChunk)) {
        const size_t end = std::min(triangles, begin + kChunk);
        for (size_t t = begin; t < end; ++t) frame.rasterizeTriangle<ShadeMode::Full>(t, sink);
      }
      perThread[w] = sink.counters;
    });
  for (std::thread& t : workers) t.join();
  for (const CaptureCounters& c : perThread) total.add(c);
  return total;
}

}  // namespace

Isa captureIsaFor(const RasterFrame& frame, const MethodDesc& method, CaptureMode mode) {
  if (isPeerRule(method.compositing) || method.store == StoreChoice::LinkedList) return Isa::Scalar;
  if (frame.samples() > 1) return Isa::Scalar;  // the 8-lane kernel tests pixel centres only
  return captureIsa(method, mode);
}

CaptureCounters capture(const RasterFrame& frame, const MethodDesc& method,
                        const Allocation& allocation, const OccupancyMap* occupancy,
                        CaptureMode mode, Stores& stores) {
  if (isPeerRule(method.compositing))  // wboit, mboit, mlab: peer_methods.cpp
    return capturePeer(frame, method, allocation, mode, stores);
  const bool hybrid = method.compositing == Compositing::Hybrid;
  const bool occ = occupancy != nullptr;
  const bool kplus = method.culling == CullingTest::KPlus;
  const Isa isa = captureIsaFor(frame, method, mode);
  // one instantiation per combination, so each inner loop carries only the tests it needs
  if (hybrid) {
    if (occ)
      return kplus ? runCapture<true, true, true>(frame, allocation, occupancy, mode, isa, stores)
                   : runCapture<true, true, false>(frame, allocation, occupancy, mode, isa, stores);
    return kplus ? runCapture<true, false, true>(frame, allocation, occupancy, mode, isa, stores)
                 : runCapture<true, false, false>(frame, allocation, occupancy, mode, isa, stores);
  }
  if (occ)
    return kplus ? runCapture<false, true, true>(frame, allocation, occupancy, mode, isa, stores)
                 : runCapture<false, true, false>(frame, allocation, occupancy, mode, isa, stores);
  return kplus ? runCapture<false, false, true>(frame, allocation, occupancy, mode, isa, stores)
               : runCapture<false, false, false>(frame, allocation, occupancy, mode, isa, stores);
}

}  // namespace mfr::detail
