// The passes of the peer methods, the transparency methods engines ship instead of k-buffers:
//   wboit  McGuire & Bavoil, "Weighted Blended Order-Independent Transparency", JCGT 2(2), 2013
//          (include/mfr/method/wboit.hpp): one accumulation pass, composite;
//   mboit  Muenstermann, Krumpen, Klein, Peters, "Moment-Based Order-Independent Transparency",
//          HPG 2018 (mboit.hpp): moments pass, then a second geometry pass weighting each fragment
//          by the reconstructed transmittance, composite;
//   mlab   Salvi & Vaidyanathan, "Multi-layer Alpha Blending", I3D 2014 (mlab.hpp): k blended
//          nodes per pixel (the fixed-k allocation's offsets and capacity), insertion in depth
//          order, merge of the two farthest when full, front-to-back resolve;
//   peel, dual-peel  Everitt, "Interactive Order-Independent Transparency", NVIDIA 2001; Bavoil &
//          Myers, "Order Independent Transparency with Dual Depth Peeling", NVIDIA 2008
//          (peel.hpp): the capture repeated (runPeelPass: a geometry pass, then each pixel's step)
//          until a pass takes every fragment in range or --max-peels passes, [the tail pass].
//   stochastic, stochastic-strat  Enderton, Sintorn, Shirley, Luebke, "Stochastic Transparency",
//          I3D 2010; Laine & Karras, "Stratified Sampling for Stochastic Transparency", EGSR 2011
//          (stochastic.hpp): total-alpha and stochastic-depth passes, then the capture weighting
//          each fragment by its stochastic visibility, composite with the alpha correction;
//   hashed-alpha  Wyman & McGuire, "Hashed Alpha Testing", I3D 2017 (hashed_alpha.hpp): one pass
//          into a z-buffer of the fragments whose alpha passes a hash of their surface point (the
//          point reconstructed here, SurfacePoints).
// Each is a type (mfr/method/peer_method.hpp) run by the one template below inside render()'s pass
// structure (allocate -> [its extra passes, e.g. moments] -> capture -> resolve) on the same
// rasterizer; only the per-pixel update and the resolve differ from the k-buffer family.
// Tile-owned mode: a pixel's fragments arrive in primitive order on one worker (no locks, the
// float sums in a fixed order). Fragment-parallel mode: any interleaving, each update under the
// pixel's spin-lock (the lock word MemoryModel charges in that mode or for mlab).
#include <atomic>
#include <cmath>
#include <thread>
#include <type_traits>

#include "mfr/scene/camera.hpp"
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

/// What one geometry pass saw: fragments generated, and those update() took (returned true; an
/// update returning nothing takes none).
struct FragmentTally {
  uint64_t generated = 0, taken = 0;
};

/// A rasterizer sink: emit() hands the shaded fragment to fn; accept() is the early test before
/// shading (depth peeling rejects a pixel's fragments in front of its peeled layers there).
template <class Accept, class F>
struct AcceptEmit {
  Accept acceptFn;
  F fn;
  bool accept(uint32_t pixel, float depth) const { return acceptFn(pixel, depth); }
  void emit(const Fragment& f) { fn(f); }
};
template <class Accept, class F>
AcceptEmit(Accept, F) -> AcceptEmit<Accept, F>;

struct AcceptAll {
  bool operator()(uint32_t, float) const { return true; }
};

// Runs update(fragment) for every shaded fragment `accept` lets through.
template <class Update, class Accept = AcceptAll>
FragmentTally forEachFragment(const RasterFrame& frame, CaptureMode mode, Stores& stores,
                              Update&& update, Accept accept = {}) {
  const auto apply = [&](const Fragment& f, FragmentTally& t) {
    ++t.generated;
    if constexpr (std::is_same_v<decltype(update(f)), bool>) {
      t.taken += update(f) ? 1 : 0;
    } else {
      update(f);
    }
  };
  FragmentTally total;
  if (mode == CaptureMode::TileOwned) {
    std::vector<FragmentTally> perTile(static_cast<size_t>(frame.tileCount()));
    frame.forEachTile([&](int tile) {
      FragmentTally t;
      frame.rasterizeTile<ShadeMode::Full>(
          tile, AcceptEmit{accept, [&](const Fragment& f) { apply(f, t); }});
      perTile[tile] = t;
    });
    for (const FragmentTally& t : perTile) {
      total.generated += t.generated;
      total.taken += t.taken;
    }
    return total;
  }
  const size_t triangles = frame.setups().size();
  constexpr size_t kChunk = 16;
  std::atomic<size_t> cursor{0};
  std::vector<FragmentTally> perThread(static_cast<size_t>(frame.threads()));
  std::vector<std::thread> workers;
  for (int w = 0; w < frame.threads(); ++w)
    workers.emplace_back([&, w] {
      FragmentTally t;
      auto sink = AcceptEmit{accept, [&](const Fragment& f) {
                               lockPixel(stores.locks, f.pixel);
                               apply(f, t);
                               unlockPixel(stores.locks, f.pixel);
                             }};
      for (size_t begin = cursor.fetch_add(kChunk); begin < triangles;
           begin = cursor.fetch_add(kChunk)) {
        const size_t end = std::min(triangles, begin + kChunk);
        for (size_t t = begin; t < end; ++t) frame.rasterizeTriangle<ShadeMode::Full>(t, sink);
      }
      perThread[w] = t;
    });
  for (std::thread& t : workers) t.join();
  for (const FragmentTally& t : perThread) {
    total.generated += t.generated;
    total.taken += t.taken;
  }
  return total;
}

/// The world-space point of the surface a fragment shows and its pixel's footprint there
/// (PeerFragment::position, footprint), from the pixel, the window depth and the frame's camera:
/// the view depth from the depth (GL's perspective, the frame's fitted clip planes), the view-space
/// point along the pixel centre's ray, back to world space.
class SurfacePoints {
 public:
  explicit SurfacePoints(const RasterFrame& frame)
      : frame_(frame),
        inverseView_(glm::inverse(viewMatrix(frame.camera()))),
        near_(frame.camera().zNear),
        far_(frame.camera().zFar),
        rays_(frame.shadingInputs()) {}

  void locate(PeerFragment& f) const {
    const glm::vec2 at = frame_.shadedPosition(f.pixel);
    f.position = method_math::surfacePoint(
        at.x, at.y, f.depth, near_, far_,
        glm::vec4(rays_.rayScaleX, rays_.rayBiasX, rays_.rayScaleY, rays_.rayBiasY), inverseView_,
        f.footprint);
  }

 private:
  const RasterFrame& frame_;
  glm::mat4 inverseView_;
  float near_, far_;
  ShadingInputs rays_;
};

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

  static FragmentTally pass(const RasterFrame& frame, const Allocation& a, CaptureMode mode,
                            Stores& stores, int pass) {
    const SurfacePoints surface(frame);
    const auto update = [&](const Fragment& f) {
      const uint32_t p = f.pixel;
      const PeerPixel<Slot> px{slotsOf(stores, a, p), stores.counts[p],
                               Peer::kNodes ? a.capacity[p] : 1u};
      if constexpr (peerTakesFragment<Peer>()) {
        PeerFragment pf{f.pixel, f.depth, f.rgba, f.prim};
        if constexpr (peerNeedsPosition<Peer>()) surface.locate(pf);
        return Peer::add(px, pass, pf);
      } else {
        return Peer::add(px, pass, f.depth, f.rgba);
      }
    };
    if constexpr (peerRepeatsCapture<Peer>()) {
      // depth peeling: a fragment whose depth alone puts it outside the range still to peel is
      // rejected before shading (the bounds change only between passes)
      return forEachFragment(frame, mode, stores, update, [&](uint32_t p, float depth) {
        return Peer::mayRemain(slotsOf(stores, a, p), depth);
      });
    } else {
      return forEachFragment(frame, mode, stores, update);
    }
  }
};

/// Runs f(p) for every pixel, tile by tile on the frame's workers; returns the sum of f's results.
template <class F>
uint64_t sumOverPixels(const RasterFrame& frame, F&& f) {
  std::vector<uint64_t> perTile(static_cast<size_t>(frame.tileCount()), 0);
  frame.forEachTile([&](int tile) {
    const TileRect r = frame.tileRect(tile);
    uint64_t sum = 0;
    for (int y = r.y0; y <= r.y1; ++y)
      for (int x = r.x0; x <= r.x1; ++x) sum += f(static_cast<uint32_t>(y) * frame.width() + x);
    perTile[tile] = sum;
  });
  uint64_t total = 0;
  for (uint64_t s : perTile) total += s;
  return total;
}

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

PeelPassCounters runPeelPass(const RasterFrame& frame, const MethodDesc& method,
                             const Allocation& allocation, CaptureMode mode, Stores& stores,
                             int pass) {
  PeelPassCounters c;
  visitPeer(method.compositing, [&]<class Peer>() {
    if constexpr (peerRepeatsCapture<Peer>()) {
      const FragmentTally t = PeerRun<Peer>::pass(frame, allocation, mode, stores, pass);
      c.generated = t.generated;
      c.inRange = t.taken;
      // the step between passes: each pixel's layer blended, its bounds advanced
      c.peeled = sumOverPixels(frame, [&](uint32_t p) {
        const uint32_t m = Peer::endPass(PeerRun<Peer>::slotsOf(stores, allocation, p));
        stores.counts[p] += m;
        return uint64_t{m};
      });
    }
  });
  return c;
}

void runPeelTail(const RasterFrame& frame, const MethodDesc& method, const Allocation& allocation,
                 CaptureMode mode, Stores& stores) {
  visitPeer(method.compositing, [&]<class Peer>() {
    if constexpr (peerRepeatsCapture<Peer>())
      (void)forEachFragment(
          frame, mode, stores,
          [&](const Fragment& f) {
            const uint32_t p = f.pixel;
            if (Peer::remains(PeerRun<Peer>::slotsOf(stores, allocation, p), f.depth, f.rgba))
              stores.tails[p].add(f.rgba);
          },
          [&](uint32_t p, float depth) {
            return Peer::mayRemain(PeerRun<Peer>::slotsOf(stores, allocation, p), depth);
          });
  });
}

CaptureCounters capturePeer(const RasterFrame& frame, const MethodDesc& method,
                            const Allocation& allocation, CaptureMode mode, Stores& stores) {
  CaptureCounters c;
  visitPeer(method.compositing, [&]<class Peer>() {
    const int capturePass = static_cast<int>(Peer::kExtraPasses.size());
    c.generated = PeerRun<Peer>::pass(frame, allocation, mode, stores, capturePass).generated;
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
          const typename Peer::Slot* slots = PeerRun<Peer>::slotsOf(stores, allocation, p);
          if constexpr (peerRepeatsCapture<Peer>())
            image.pixels[p] = Peer::composite(
                slots, stores.tails.size() ? &stores.tails[p] : nullptr, background);
          else
            image.pixels[p] = Peer::composite(slots, stores.counts[p], background);
        }
    });
  });
  return image;
}

}  // namespace mfr::detail
