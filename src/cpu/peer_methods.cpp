// The passes of the peer methods, the transparency methods engines ship instead of k-buffers:
//   wboit  McGuire & Bavoil, "Weighted Blended Order-Independent Transparency", JCGT 2(2), 2013
//          (include/mfr/method/wboit.hpp): one accumulation pass, composite;
//   mboit  Muenstermann, Krumpen, Klein, Peters, "Moment-Based Order-Independent Transparency",
//          HPG 2018 (mboit.hpp): moments pass, then a second geometry pass weighting each fragment
//          by the reconstructed transmittance, composite;
//   mlab   Salvi & Vaidyanathan, "Multi-layer Alpha Blending", I3D 2014 (mlab.hpp): k blended
//          nodes per pixel (the fixed-k allocation's offsets and capacity), insertion in depth
//          order, merge of the two farthest when full, front-to-back resolve.
// Each is a type (mfr/method/peer_method.hpp) run by the one template below inside render()'s pass
// structure (allocate -> [its extra passes, e.g. moments] -> capture -> resolve) on the same
// rasterizer; only the per-pixel update and the resolve differ from the k-buffer family.
// Tile-owned mode: a pixel's fragments arrive in primitive order on one worker (no locks, the
// float sums in a fixed order). Fragment-parallel mode: any interleaving, each update under the
// pixel's spin-lock (the lock word MemoryModel charges in that mode or for mlab).
#include <atomic>
#include <thread>

#include "pipeline.hpp"

namespace mfr::detail {
namespace {

void lockPixel(std::vector<uint32_t>& locks, uint32_t p) {
  std::atomic_ref<uint32_t> a(locks[p]);
  int spins = 0;
  while (a.exchange(1, std::memory_order_acquire) != 0) {
    while (a.load(std::memory_order_relaxed) != 0) {
      if (++spins > 64) std::this_thread::yield();
    }
  }
}

void unlockPixel(std::vector<uint32_t>& locks, uint32_t p) {
  std::atomic_ref<uint32_t>(locks[p]).store(0, std::memory_order_release);
}

// Runs update(fragment) for every shaded fragment; returns the fragments generated.
template <class Update>
uint64_t forEachFragment(const RasterFrame& frame, CaptureMode mode, Stores& stores,
                         Update&& update) {
  if (mode == CaptureMode::TileOwned) {
    std::vector<uint64_t> perTile(static_cast<size_t>(frame.tileCount()), 0);
    frame.forEachTile([&](int tile) {
      uint64_t n = 0;
      frame.rasterizeTile<ShadeMode::Full>(tile, EmitAll{[&](const Fragment& f) {
                                             ++n;
                                             update(f);
                                           }});
      perTile[tile] = n;
    });
    uint64_t total = 0;
    for (uint64_t n : perTile) total += n;
    return total;
  }
  const size_t triangles = frame.setups().size();
  constexpr size_t kChunk = 16;
  std::atomic<size_t> cursor{0};
  std::vector<uint64_t> perThread(static_cast<size_t>(frame.threads()), 0);
  std::vector<std::thread> workers;
  for (int w = 0; w < frame.threads(); ++w)
    workers.emplace_back([&, w] {
      uint64_t n = 0;
      auto sink = EmitAll{[&](const Fragment& f) {
        ++n;
        lockPixel(stores.locks, f.pixel);
        update(f);
        unlockPixel(stores.locks, f.pixel);
      }};
      for (size_t begin = cursor.fetch_add(kChunk); begin < triangles;
           begin = cursor.fetch_add(kChunk)) {
        const size_t end = std::min(triangles, begin + kChunk);
        for (size_t t = begin; t < end; ++t) frame.rasterizeTriangle<ShadeMode::Full>(t, sink);
      }
      perThread[w] = n;
    });
  for (std::thread& t : workers) t.join();
  uint64_t total = 0;
  for (uint64_t n : perThread) total += n;
  return total;
}

/// The CPU engine's run of one peer method (peer_method.hpp): its buffer, each of its geometry
/// passes, its resolve.
template <class Peer>
struct PeerRun {
  using Slot = typename Peer::Slot;

  static Slot* slotsOf(Stores& stores, const Allocation& a, uint32_t p) {
    Slot* base = stores.peer.template data<Slot>();
    if constexpr (Peer::kNodes) return base + a.offsets[p];
    return base + p;
  }

  static uint64_t pass(const RasterFrame& frame, const Allocation& a, CaptureMode mode,
                       Stores& stores, int pass) {
    return forEachFragment(frame, mode, stores, [&](const Fragment& f) {
      const uint32_t p = f.pixel;
      Peer::add(PeerPixel<Slot>{slotsOf(stores, a, p), stores.counts[p],
                                Peer::kNodes ? a.capacity[p] : 1u},
                pass, f.depth, f.rgba);
    });
  }
};

}  // namespace

bool isPeerRule(Compositing c) {
  return !kBufferFamilyRule(c);
}

void allocatePeerStores(const MethodDesc& method, const Allocation& allocation, size_t pixels,
                        Stores& stores) {
  visitPeer(method.compositing, [&]<class Peer>() {
    stores.peer.assign<typename Peer::Slot>(Peer::kNodes ? allocation.slots : pixels);
    stores.peerHoldsNodes = Peer::kNodes;
  });
}

void runPeerPass(const RasterFrame& frame, const MethodDesc& method, const Allocation& allocation,
                 CaptureMode mode, Stores& stores, int pass) {
  visitPeer(method.compositing, [&]<class Peer>() {
    (void)PeerRun<Peer>::pass(frame, allocation, mode, stores, pass);
  });
}

CaptureCounters capturePeer(const RasterFrame& frame, const MethodDesc& method,
                            const Allocation& allocation, CaptureMode mode, Stores& stores) {
  CaptureCounters c;
  visitPeer(method.compositing, [&]<class Peer>() {
    const int capturePass = static_cast<int>(Peer::kExtraPasses.size());
    c.generated = PeerRun<Peer>::pass(frame, allocation, mode, stores, capturePass);
    if constexpr (Peer::kNodes) {
      // a fragment either opened a node or was blended into a farther one (a merge)
      uint64_t nodes = 0;
      for (uint32_t n : stores.counts) nodes += n;
      c.inserted = nodes;
      c.evicted = c.generated - nodes;
    } else {
      c.inserted = c.generated;
    }
  });
  return c;
}

ImageRGB resolvePeer(const RasterFrame& frame, const MethodDesc& method,
                     const Allocation& allocation, Stores& stores, glm::vec3 background) {
  ImageRGB image(frame.width(), frame.height());
  visitPeer(method.compositing, [&]<class Peer>() {
    frame.forEachTile([&](int tile) {
      const TileRect r = frame.tileRect(tile);
      for (int y = r.y0; y <= r.y1; ++y)
        for (int x = r.x0; x <= r.x1; ++x) {
          const uint32_t p = static_cast<uint32_t>(y) * frame.width() + x;
          image.pixels[p] = Peer::composite(PeerRun<Peer>::slotsOf(stores, allocation, p),
                                            stores.counts[p], background);
        }
    });
  });
  return image;
}

}  // namespace mfr::detail
