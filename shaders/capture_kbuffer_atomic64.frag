// Per-pixel memory (pixel p; bindings in shared_layout.h):
//
//   nodes (kBindNodes, uint64 = 8 B)   slots [p * k, p * k + k), kept sorted nearest first
//     slot:  colour word in the low 32 bits, depth bits high while capturing (the 64-bit order);
//            swap_node_words.comp then restores the engine's uvec2 (depth, colour) layout
//     empty: depth bits kFarDepthBits (+inf): the walk ends at the first empty slot
//
// Bytes per pixel: 8 k + 4 (the count pass's counter); no lock word is needed, though the memory
// model charges the fixed-k stores' lock (what the spin-lock capture uses).
//
// Fixed-k k-buffer capture with 64-bit atomics (the k-buffer paper's "atomicMin" variant, variable
// k-buffer paper /work/shared/papers/variable-k-buffer-importance-maps.md sec. 4: the fixed k-buffer
// "exploits atomicMin hardware instructions" where the others need a spin-lock): compiled only when
// the driver offers GL_NV_shader_atomic_int64 and GL_ARB_gpu_shader_int64 (the engine's prelude
// enables them). Pixel p's k slots hold 64-bit nodes (depth bits high, colour low: the node order)
// kept sorted, initialised to the far node. A fragment walks the slots with atomicMin, carrying
// the larger of (its value, the slot's old value) on: the k nearest stay, in order, whatever the
// arrival order; an empty slot (the far node) ends the walk. No lock, no critical section. The
// k+ test rejects a fragment behind the last slot before the walk. Words are (colour, depth) in
// memory: swap_node_words.comp restores the engine's (depth, colour) uvec2 layout afterwards.
layout(std430, binding = kBindNodes) coherent buffer Nodes {
  uint64_t nodes[];
};
layout(std430, binding = kBindCaptureStats) buffer CaptureStats {
  uint culled[];  // kCaptureStatSlots x kCaptureStatStride: occupancy, k+ (shared_layout.h)
};
uniform uint uK;

void main() {
  FragmentData f;
  if (!rasterFragment(f)) discard;
  vec4 base;
  if (!surface(f, false, base)) discard;
  countInCapture(f);
  const uint first = uint(f.pixel) * uK;
  const uint64_t far = packUint2x32(uvec2(0u, kFarDepthBits));
  uint64_t v = packUint2x32(uvec2(shade(f, base), floatBitsToUint(fragmentDepth(f))));
  if (v >= nodes[first + uK - 1u]) {  // k+ test: the last slot only decreases
    atomicAdd(culled[captureStatSlot(f.px) + 1u], 1u);
    return;
  }
  for (uint i = 0u; i < uK; ++i) {
    const uint64_t old = atomicMin(nodes[first + i], v);
    if (old == far) break;
    v = max(old, v);
  }
}
