#include "mfr/method/memory_model.hpp"

#include "mfr/capture/occupancy_map.hpp"

namespace mfr {

MemoryModel MemoryModel::of(const MethodDesc& method, bool fragmentParallel) {
  MemoryModel m;
  const bool prefixSum = method.allocation != AllocationPolicy::FixedK;
  m.offset = prefixSum ? 4 : 0;
  m.lock = method.perPixelLock || fragmentParallel ? 4 : 0;
  m.occupancy = method.occupancyWords > 0 ? OccupancyMap::bytesPerPixel(method.occupancyWords) : 0;
  m.tail = method.compositing == Compositing::Hybrid ? 20 : 0;
  m.previous = method.allocation == AllocationPolicy::Importance &&
                       method.importanceSource == ImportanceSource::Heuristic
                   ? 1
                   : 0;
  m.image = method.allocation == AllocationPolicy::DynamicK ? kHistogramBins * 4 : 0;
  return m;
}

std::map<std::string, uint64_t> MemoryModel::breakdown(uint64_t pixels, uint64_t slots) const {
  std::map<std::string, uint64_t> bytes;
  bytes["nodes"] = slots * kNodeBytes;
  bytes["counters"] = pixels * counter;
  if (offset) bytes["offsets"] = pixels * offset;
  if (lock) bytes["locks"] = pixels * lock;
  if (occupancy) bytes["occupancy"] = pixels * occupancy;
  if (tail) bytes["tail"] = pixels * tail;
  if (previous) bytes["previous_frame"] = pixels * previous;
  if (image) bytes["histogram"] = image;
  return bytes;
}

}  // namespace mfr
