#include "mfr/method/memory_model.hpp"

#include "mfr/method/peer_method.hpp"

namespace mfr {

MemoryModel MemoryModel::of(const MethodDesc& method, bool fragmentParallel) {
  MemoryModel m;
  const bool noNodes = method.allocation == AllocationPolicy::NoNodes;
  const bool prefixSum = method.allocation != AllocationPolicy::FixedK && !noNodes;
  m.counter = noNodes ? 0 : 4;
  m.offset = prefixSum ? 4 : 0;
  m.lock = method.perPixelLock || fragmentParallel ? 4 : 0;
  m.occupancy = method.occupancyWords > 0 ? occupancyBytesPerPixel(method.occupancyWords) : 0;
  m.tail = method.compositing == Compositing::Hybrid || method.peelTail ? 20 : 0;
  m.previous = method.allocation == AllocationPolicy::Importance &&
                       method.importanceSource == ImportanceSource::Heuristic
                   ? 1
                   : 0;
  visitPeer(method.compositing, [&]<class Peer>() {
    if constexpr (Peer::kNodes)
      m.node = sizeof(typename Peer::Slot);
    else
      m.accum = sizeof(typename Peer::Slot);
  });
  if (noNodes) m.node = 0;
  m.image = method.allocation == AllocationPolicy::DynamicK ? kHistogramBins * 4 : 0;
  if (method.allocation == AllocationPolicy::Pool) {  // linked lists: lock-free (atomics)
    m.counter = 0;
    m.offset = 0;
    m.head = 4;
    m.poolCounter = 4;
    m.lock = method.perPixelLock ? 4 : 0;
    m.node = kLinkedNodeBytes;
  }
  return m;
}

std::map<std::string, uint64_t> MemoryModel::breakdown(uint64_t pixels, uint64_t slots) const {
  std::map<std::string, uint64_t> bytes;
  if (slots || counter || head) bytes["nodes"] = slots * node;
  if (counter) bytes["counters"] = pixels * counter;
  if (offset) bytes["offsets"] = pixels * offset;
  if (lock) bytes["locks"] = pixels * lock;
  if (occupancy) bytes["occupancy"] = pixels * occupancy;
  if (tail) bytes["tail"] = pixels * tail;
  if (previous) bytes["previous_frame"] = pixels * previous;
  if (accum) bytes["accumulators"] = pixels * accum;
  if (image) bytes["histogram"] = image;
  if (head) bytes["heads"] = pixels * head;
  if (poolCounter) bytes["pool_counter"] = poolCounter;
  return bytes;
}

}  // namespace mfr
