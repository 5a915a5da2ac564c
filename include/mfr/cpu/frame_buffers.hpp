// Buffers kept from one CPU render to the next: the node pool (and the linked lists' pool), the
// per-pixel counters, locks and list heads. A frame writes them in full or in large part, and
// freshly allocated memory costs a page fault per 4 KiB on its first write (the layers frame at
// 1024x1024: about 14,000 faults, 10-20 ms of its ~100 ms, measured 2026-12-05), while a GPU
// renderer keeps its buffers from frame to frame. Pass the same FrameBuffers to consecutive
// renders (RenderOptions::reuse; CpuEngine keeps one) and they are reused; each render still
// clears and fills them as a fresh one would, so the output is the same bits.
#pragma once

#include <atomic>
#include <memory>

namespace mfr {
namespace detail {
struct Stores;
}

class FrameBuffers {
 public:
  FrameBuffers();
  ~FrameBuffers();
  FrameBuffers(const FrameBuffers&) = delete;
  FrameBuffers& operator=(const FrameBuffers&) = delete;

  /// Frees what is kept.
  void release();

  /// The kept buffers for one render, or none while another render holds them (one at a time;
  /// a concurrent render allocates its own).
  std::unique_ptr<detail::Stores> take();
  /// Keeps `stores` for the next render; only by the render whose take() gave it buffers.
  void give(std::unique_ptr<detail::Stores> stores);

 private:
  std::unique_ptr<detail::Stores> kept_;
  std::atomic<bool> taken_{false};
};

}  // namespace mfr
