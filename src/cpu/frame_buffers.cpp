#include "mfr/cpu/frame_buffers.hpp"

#include "pipeline.hpp"

namespace mfr {

FrameBuffers::FrameBuffers() = default;
FrameBuffers::~FrameBuffers() = default;

void FrameBuffers::release() {
  if (!taken_.exchange(true)) {
    kept_.reset();
    taken_ = false;
  }
}

std::unique_ptr<detail::Stores> FrameBuffers::take() {
  if (taken_.exchange(true)) return nullptr;
  return kept_ ? std::move(kept_) : std::make_unique<detail::Stores>();
}

void FrameBuffers::give(std::unique_ptr<detail::Stores> stores) {  // after a successful take()
  kept_ = std::move(stores);
  taken_ = false;
}

}  // namespace mfr
