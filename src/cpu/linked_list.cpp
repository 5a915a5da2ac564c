// The CPU engine's per-pixel linked lists (J. C. Yang, J. Hensley, H. Gruen, N. Thibieroz,
// "Real-Time Concurrent Linked List Construction on the GPU", EGSR 2010; mfr/method/
// linked_list.hpp): capture into a head word per pixel and one pool of F(M) nodes, then a resolve
// that walks each list, sorts its nodes and composites them (kbuffer or hybrid).
//
// Determinism: the fragments that get a node are those a serial GPU would admit, in primitive
// order and within a triangle in its scanline order, for any number of threads:
//   1. admission (tile-parallel, coverage only): each tile's fragments per primitive, as runs
//      (a tile sees its triangles in primitive order);
//   2. on one thread: the fragments per primitive, their prefix sum over primitives and the
//      primitive b where the pool runs out with r nodes left; the pixels of b's first r fragments
//      (b alone rasterized, its pieces in set-up order, each row by row); then each tile's admitted
//      fragments and their prefix sum over tiles, the tile's first node;
//   3. capture (tile-parallel, shaded): a fragment of a primitive before b, or of b at an admitted
//      pixel (a triangle covers a pixel once), takes the tile's next node and becomes its pixel's
//      head; any other goes to the hybrid tail or is lost.
// Node indices run tile by tile, in primitive order within a tile; each list is newest first, so
// the pool's bytes, the lists and the image are the same for any number of threads. With a pool
// that holds every fragment the admitted set is every fragment in any draw order (the image is
// order-independent: the resolve sorts); with an overflowing pool it depends on the draw order.
// The capture mode does not matter: the GPU's atomics need no per-pixel lock, and both modes run
// the passes above.
#include <algorithm>
#include <utility>

#include "mfr/method/linked_list.hpp"
#include "pipeline.hpp"
#include "sort_nodes.hpp"

namespace mfr::detail {

CaptureCounters captureLinkedList(const RasterFrame& frame, const MethodDesc& method,
                                  const Allocation& allocation, Stores& stores,
                                  BufferLedger& ledger) {
  const int tiles = frame.tileCount();
  const uint64_t poolSize = allocation.slots;
  const bool hybrid = method.compositing == Compositing::Hybrid;

  // 1. admission pass: (primitive, fragments) runs per tile
  std::vector<std::vector<std::pair<uint32_t, uint32_t>>> runs(static_cast<size_t>(tiles));
  frame.forEachTile([&](int tile) {
    auto& r = runs[static_cast<size_t>(tile)];
    frame.rasterizeTile<ShadeMode::Coverage>(tile, EmitAll{[&](const Fragment& f) {
                                               if (!r.empty() && r.back().first == f.prim)
                                                 ++r.back().second;
                                               else
                                                 r.emplace_back(f.prim, 1u);
                                             }});
  });

  // 2. the boundary primitive and each tile's first node
  uint32_t primitives = 0;
  for (const TriangleSetup& s : frame.setups()) primitives = std::max(primitives, s.prim + 1);
  std::vector<uint64_t> perPrimitive(primitives, 0);
  uint64_t runBytes = 0;
  for (const auto& r : runs) {
    runBytes += r.capacity() * sizeof(r[0]);
    for (const auto& [prim, n] : r) perPrimitive[prim] += n;
  }
  uint64_t generated = 0;
  for (uint64_t n : perPrimitive) generated += n;
  uint32_t boundary = primitives;  // every primitive before it is admitted whole
  uint64_t room = 0;               // the boundary primitive's admitted fragments
  if (generated > poolSize) {
    uint64_t before = 0;
    for (uint32_t prim = 0; prim < primitives; ++prim) {
      if (before + perPrimitive[prim] > poolSize) {
        boundary = prim;
        room = poolSize - before;
        break;
      }
      before += perPrimitive[prim];
    }
  }
  std::vector<uint32_t> admittedPixels;  // the boundary primitive's first `room` pixels, sorted
  if (room > 0) {
    for (size_t s = 0; s < frame.setups().size() && admittedPixels.size() < room; ++s)
      if (frame.setups()[s].prim == boundary)
        frame.rasterizeTriangle<ShadeMode::Coverage>(s, EmitAll{[&](const Fragment& f) {
                                                       if (admittedPixels.size() < room)
                                                         admittedPixels.push_back(f.pixel);
                                                     }});
    std::sort(admittedPixels.begin(), admittedPixels.end());
  }
  const int tileSize = frame.tileSize();
  const int tilesX = (frame.width() + tileSize - 1) / tileSize;
  std::vector<uint64_t> firstNode(static_cast<size_t>(tiles) + 1, 0);
  for (int tile = 0; tile < tiles; ++tile)
    for (const auto& [prim, n] : runs[static_cast<size_t>(tile)])
      if (prim < boundary) firstNode[static_cast<size_t>(tile) + 1] += n;
  for (uint32_t p : admittedPixels) {
    const int x = static_cast<int>(p % static_cast<uint32_t>(frame.width()));
    const int y = static_cast<int>(p / static_cast<uint32_t>(frame.width()));
    ++firstNode[static_cast<size_t>((y / tileSize) * tilesX + x / tileSize) + 1];
  }
  for (size_t tile = 0; tile < static_cast<size_t>(tiles); ++tile)
    firstNode[tile + 1] += firstNode[tile];
  MFR_CHECK_LE(firstNode.back(), poolSize);
  ledger.addBytes("allocation_scratch", runBytes + perPrimitive.capacity() * sizeof(uint64_t) +
                                            admittedPixels.capacity() * sizeof(uint32_t) +
                                            firstNode.capacity() * sizeof(uint64_t));
  runs = {};
  perPrimitive = {};

  // 3. capture
  std::fill(stores.heads.begin(), stores.heads.end(), kListEnd);
  LinkedNode* pool = stores.pool.data();
  std::vector<uint64_t> generatedPerTile(static_cast<size_t>(tiles), 0);
  frame.forEachTile([&](int tile) {
    uint64_t next = firstNode[static_cast<size_t>(tile)];
    uint64_t n = 0;
    frame.rasterizeTile<ShadeMode::Full>(
        tile, EmitAll{[&](const Fragment& f) {
          ++n;
          const bool admitted =
              f.prim < boundary ||
              (f.prim == boundary &&
               std::binary_search(admittedPixels.begin(), admittedPixels.end(), f.pixel));
          if (admitted) {
            pool[next] = makeLinkedNode(f.depth, f.rgba, stores.heads[f.pixel]);
            stores.heads[f.pixel] = static_cast<uint32_t>(next++);
            ++stores.counts[f.pixel];
          } else if (hybrid) {
            stores.toTail(f.pixel, makeNode(f));
          }
        }});
    MFR_CHECK_EQ(next, firstNode[static_cast<size_t>(tile) + 1]);
    generatedPerTile[static_cast<size_t>(tile)] = n;
  });
  CaptureCounters c;
  for (uint64_t n : generatedPerTile) c.generated += n;
  MFR_CHECK_EQ(c.generated, generated);
  c.inserted = firstNode.back();
  c.rejected = c.generated - c.inserted;
  return c;
}

ImageRGB resolveLinkedList(const RasterFrame& frame, const MethodDesc& method, Stores& stores,
                           glm::vec3 background) {
  const LinkedNode* pool = stores.pool.data();
  return resolveSortedNodes(frame, method, stores, background,
                            [&](size_t p, uint32_t n, std::vector<FragmentNode>& keys) {
                              keys.clear();
                              for (uint32_t i = stores.heads[p]; i != kListEnd; i = pool[i].next)
                                keys.push_back(sortKey(pool[i]));
                              MFR_CHECK_EQ(keys.size(), n);
                              return static_cast<const FragmentNode*>(keys.data());
                            });
}

void exportLinkedLists(const Stores& stores, RenderOutput& out) {
  const size_t pixels = stores.heads.size();
  out.offsets.assign(pixels, 0);
  out.counts = stores.counts;
  out.nodes.clear();
  for (size_t p = 0; p < pixels; ++p) {
    out.offsets[p] = out.nodes.size();
    for (uint32_t i = stores.heads[p]; i != kListEnd; i = stores.pool.data()[i].next)
      out.nodes.push_back(sortKey(stores.pool.data()[i]));
  }
}

}  // namespace mfr::detail
