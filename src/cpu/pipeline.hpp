// Internal state shared by the passes of render(): the allocation and the per-pixel stores.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <map>
#include <memory>
#include <new>
#include <optional>
#include <string>
#include <type_traits>
#include <typeinfo>
#include <vector>

#include "mfr/core/isa.hpp"
#include "mfr/cpu/fragment_stores.hpp"
#include "mfr/cpu/occupancy_map.hpp"
#include "mfr/cpu/render.hpp"
#include "mfr/method/allocation.hpp"
#include "mfr/method/compositing.hpp"
#include "mfr/method/linked_list.hpp"
#include "mfr/method/memory_model.hpp"
#include "mfr/method/peer_method.hpp"
#include "sort_nodes.hpp"

namespace mfr::detail {

/// The CPU engine's measured memory: each buffer's bytes, added where it is allocated.
class BufferLedger {
 public:
  template <class Vector>
  void add(const char* category, const Vector& v) {
    addBytes(category, v.capacity() * sizeof(typename Vector::value_type));
  }
  void addBytes(const char* category, uint64_t bytes) {
    if (bytes) bytes_[category] += bytes;
  }
  void addAll(const std::map<std::string, uint64_t>& other) {
    for (const auto& [category, bytes] : other) bytes_[category] += bytes;
  }
  const std::map<std::string, uint64_t>& byCategory() const { return bytes_; }
  uint64_t total() const {
    uint64_t t = 0;
    for (const auto& [category, bytes] : bytes_) t += bytes;
    return t;
  }

 private:
  std::map<std::string, uint64_t> bytes_;
};

struct CaptureCounters {
  uint64_t generated = 0, culledOccupancy = 0, culledKPlus = 0, rejected = 0, inserted = 0,
           evicted = 0;
  void add(const CaptureCounters& o) {
    generated += o.generated;
    culledOccupancy += o.culledOccupancy;
    culledKPlus += o.culledKPlus;
    rejected += o.rejected;
    inserted += o.inserted;
    evicted += o.evicted;
  }
};

/// Fixed-size array that is not zero-filled on allocation: the node pool is written before it is
/// read (slots at and above a pixel's count are never read), so clearing it would only cost time.
/// A buffer reused from an earlier frame (FrameBuffers) keeps its block when it holds n and is
/// not more than twice as large.
template <class T>
class UninitializedBuffer {
 public:
  void allocate(size_t n) {
    if (n <= capacity_ && capacity_ <= 2 * n) {
      size_ = n;
      return;
    }
    data_.reset();
    data_.reset(n ? new T[n] : nullptr);
    size_ = capacity_ = n;
  }
  T* data() { return data_.get(); }
  const T* data() const { return data_.get(); }
  size_t size() const { return size_; }

 private:
  std::unique_ptr<T[]> data_;
  size_t size_ = 0;
  size_t capacity_ = 0;
};

/// Fixed-size array of zero bytes from calloc: a large one comes as fresh pages the kernel zeroes
/// when first touched, so the pixels no fragment reaches cost neither a clear nor a page (a hybrid
/// tail per pixel is 20 MB at 1024x1024). T must be trivially copyable, all-zero bytes its value.
template <class T>
class ZeroedBuffer {
  static_assert(std::is_trivially_copyable_v<T>);

 public:
  void allocate(size_t n) {
    data_.reset();
    size_ = 0;
    if (n == 0) return;
    data_.reset(static_cast<T*>(std::calloc(n, sizeof(T))));
    if (!data_) throw std::bad_alloc();
    size_ = n;
  }
  T& operator[](size_t i) { return data_.get()[i]; }
  const T& operator[](size_t i) const { return data_.get()[i]; }
  size_t size() const { return size_; }
  uint64_t bytes() const { return static_cast<uint64_t>(size_) * sizeof(T); }

 private:
  struct Free {
    void operator()(T* p) const { std::free(p); }
  };
  std::unique_ptr<T, Free> data_;
  size_t size_ = 0;
};

/// A peer method's buffer (peer_method.hpp): its Slots, one per pixel or k(p) per pixel, of the
/// type the method names, value-initialised (each Slot's own defaults) by assign.
class PeerBuffer {
 public:
  template <class Slot>
  void assign(size_t n) {
    storage_ =
        std::shared_ptr<void>(new Slot[n](), [](void* p) { delete[] static_cast<Slot*>(p); });
    type_ = &typeid(Slot);
    bytes_ = n * sizeof(Slot);
  }
  template <class Slot>
  Slot* data() {
    MFR_CHECK(type_ && *type_ == typeid(Slot));
    return static_cast<Slot*>(storage_.get());
  }
  uint64_t bytes() const { return bytes_; }

 private:
  std::shared_ptr<void> storage_;
  const std::type_info* type_ = nullptr;
  uint64_t bytes_ = 0;
};

struct Stores {
  UninitializedBuffer<FragmentNode> nodes;
  std::vector<uint32_t> counts;
  std::vector<uint32_t> locks;
  ZeroedBuffer<HybridTail> tails;  // empty unless hybrid
  PeerBuffer peer;                 // the peer method's accumulators or nodes (peer_methods.cpp)
  bool peerHoldsNodes = false;     // the peer buffer holds nodes (mlab), not accumulators
  std::vector<uint32_t> heads;     // linked lists: each pixel's newest node (kListEnd: none)
  UninitializedBuffer<LinkedNode> pool;  // linked lists: the node pool
  Allocation spare;  // an earlier frame's offsets and store kinds, for allocate() to take over
  /// Per-pixel multisampled storage: the samples of the coverage masks in the nodes' depths
  /// (core/samples.hpp), which weight a node that goes to the hybrid tail; 0 otherwise.
  int maskSamples = 0;
  void toTail(uint32_t p, FragmentNode node) {
    if (maskSamples)
      tails[p].addCovered(node, maskSamples);
    else
      tails[p].add(nodeColor(node));
  }
};

/// The instruction set capture() runs this method on (what the statistics report as "isa").
Isa captureIsaFor(const RasterFrame& frame, const MethodDesc& method, CaptureMode mode);

/// The capture pass: every fragment through occupancy test, k+ test and store insertion.
CaptureCounters capture(const RasterFrame& frame, const MethodDesc& method,
                        const Allocation& allocation, const OccupancyMap* occupancy,
                        CaptureMode mode, Stores& stores);

/// The peer methods (mfr/method/peer_method.hpp: wboit, mboit, mlab) through one template: their
/// buffer, their extra geometry passes (pass i of Peer::kExtraPasses), the capture (accumulation
/// or MLAB insertion; counts[p] is the fragments accumulated, or MLAB's nodes in use) and the
/// resolve. Fragment-parallel mode takes the per-pixel spin-lock around each update.
bool isPeerRule(Compositing c);
void allocatePeerStores(const MethodDesc& method, const Allocation& allocation, size_t pixels,
                        Stores& stores);
void runPeerPass(const RasterFrame& frame, const MethodDesc& method, const Allocation& allocation,
                 CaptureMode mode, Stores& stores, int pass);
/// Depth peeling (peerRepeatsCapture): one geometry pass `pass` and each pixel's step after it;
/// the fragments generated, those still in range (not peeled before the pass) and those the step
/// peeled. Every fragment in range was peeled when inRange == peeled.
struct PeelPassCounters {
  uint64_t generated = 0, inRange = 0, peeled = 0;
};
PeelPassCounters runPeelPass(const RasterFrame& frame, const MethodDesc& method,
                             const Allocation& allocation, CaptureMode mode, Stores& stores,
                             int pass);
/// After the last peel pass: the fragments that remain into the pixels' hybrid tails.
void runPeelTail(const RasterFrame& frame, const MethodDesc& method, const Allocation& allocation,
                 CaptureMode mode, Stores& stores);
CaptureCounters capturePeer(const RasterFrame& frame, const MethodDesc& method,
                            const Allocation& allocation, CaptureMode mode, Stores& stores);
ImageRGB resolvePeer(const RasterFrame& frame, const MethodDesc& method,
                     const Allocation& allocation, Stores& stores, glm::vec3 background);

/// Per-pixel linked lists (mfr/method/linked_list.hpp, src/cpu/linked_list.cpp): the admission
/// pass, then the capture into heads and pool (counts[p]: the list's length; the rest to the
/// hybrid tail or lost), the same for any number of threads; the resolve (walk, sort, composite);
/// the lists as RenderOutput's nodes / offsets / counts (keepStores).
CaptureCounters captureLinkedList(const RasterFrame& frame, const MethodDesc& method,
                                  const Allocation& allocation, Stores& stores,
                                  BufferLedger& ledger);
ImageRGB resolveLinkedList(const RasterFrame& frame, const MethodDesc& method, Stores& stores,
                           glm::vec3 background);

/// The k-buffer family's resolve over the frame, for any store: each covered pixel's n = counts[p]
/// nodes, from `nodesOf(p, n, scratch)` (a pointer to them; `scratch` a per-tile vector the
/// gatherer may fill), sorted and composited by the method's rule (kbuffer or hybrid) over the
/// background. A pixel no fragment reached (no node, an empty tail) shows the rule's empty
/// composite: the same bits as compositing it, without the sort and the blend. The image starts as
/// that colour, so a tile no triangle reaches is never visited (most of a sparse view).
template <class NodesOf>
ImageRGB resolveSortedNodes(const RasterFrame& frame, const MethodDesc& method,
                            const Stores& stores, glm::vec3 background, NodesOf&& nodesOf) {
  const bool hybrid = method.compositing == Compositing::Hybrid;
  const glm::vec3 empty = hybrid ? compositeHybrid(nullptr, 0, HybridTail{}, background)
                                 : compositeKBuffer(nullptr, 0, background);
  ImageRGB image(frame.width(), frame.height(), empty);
  // per-pixel multisampled storage: each sample from the nodes that cover it (compositeSamples)
  const int masked = frame.sampleStorage() == SampleStorage::Pixel ? frame.samples() : 1;
  frame.forEachTile([&](int tile) {
    if (frame.tileBegin(tile) == frame.tileEnd(tile)) return;
    FragmentNode small[kSortNetworkSize];
    std::vector<FragmentNode> scratch, large;  // grow once per tile
    const TileRect r = frame.tileRect(tile);
    for (int y = r.y0; y <= r.y1; ++y)
      for (int x = r.x0; x <= r.x1; ++x) {
        const size_t p = static_cast<size_t>(y) * frame.width() + x;
        const uint32_t n = stores.counts[p];
        if (n == 0 && (!hybrid || stores.tails[p].count == 0)) continue;
        const FragmentNode* sorted = sortNodes(nodesOf(p, n, scratch), n, small, large);
        if (masked > 1)
          image.pixels[p] = compositeSamples(
              sorted, n, masked, hybrid ? tailBehind(stores.tails[p], background) : background);
        else
          image.pixels[p] = hybrid ? compositeHybrid(sorted, n, stores.tails[p], background)
                                   : compositeKBuffer(sorted, n, background);
      }
  });
  return image;
}
void exportLinkedLists(const Stores& stores, RenderOutput& out);

}  // namespace mfr::detail
