// The step between depth-peeling passes (mfr::PeelPixel::endPass, mfr::DualPeelPixel::endPass in
// include/mfr/method/peel.hpp): each pixel's layer found by the pass is composited as many times
// as its multiplicity (front to back with method_math.h's overStep; dual depth peeling's back
// layer back to front with underStep, once when both sides met on one key), the bounds advance
// past it, the candidates are reset; the fragments peeled are added to the pixel's count and to
// the frame's (stats.peeled), which the host compares with the pass's fragments in range.
layout(local_size_x = kResolveGroupSize) in;

layout(std430, binding = kBindAccum) buffer PeelState {
  uint state[];  // kPeelWords or kDualPeelWords per pixel (peel.frag)
};
layout(std430, binding = kBindCaptureStats) buffer PeelStats {
  uint inRange;
  uint peeled;
};
layout(std430, binding = kBindOffsets) buffer Peeled {
  uint held[];  // fragments peeled per pixel
};
layout(std430, binding = kBindColorTables) readonly buffer ColorTables {
  uint colorTables[];
};
uniform uint uPixels;
// Compile-time switches (gl_programs.cpp's peelSwitches):
//   MFR_DUAL  1: dual depth peeling
#ifndef MFR_DUAL
#define MFR_DUAL 0
#endif
const uint kDual = MFR_DUAL;
uniform float uInv255;

float srgb8ToLinear(uint code) {
  return uintBitsToFloat(colorTables[kTableLinearBase + code]);
}

// m "over" (front) or "under" (back) steps of the colour word rgba onto the four words at i
void blendLayer(uint i, uint rgba, uint m, bool back) {
  const uint a8 = rgba >> 24;
  precise float a = float(a8) * uInv255;
  const float cr = srgb8ToLinear(rgba & 0xffu), cg = srgb8ToLinear((rgba >> 8) & 0xffu),
              cb = srgb8ToLinear((rgba >> 16) & 0xffu);
  float r = uintBitsToFloat(state[i]), g = uintBitsToFloat(state[i + 1u]),
        b = uintBitsToFloat(state[i + 2u]), T = uintBitsToFloat(state[i + 3u]);
  for (uint j = 0u; j < m; ++j) {
    if (back)
      blendUnderStepScalar(r, g, b, T, a8, a, cr, cg, cb);
    else
      blendStepScalar(r, g, b, T, a8, a, cr, cg, cb);
  }
  state[i] = floatBitsToUint(r);
  state[i + 1u] = floatBitsToUint(g);
  state[i + 2u] = floatBitsToUint(b);
  state[i + 3u] = floatBitsToUint(T);
}

// key + 1 as (hi, lo)
uvec2 nextKey(uvec2 k) {
  return k.y == 0xffffffffu ? uvec2(k.x + 1u, 0u) : uvec2(k.x, k.y + 1u);
}

void main() {
  const uint group = gl_WorkGroupID.x + gl_WorkGroupID.y * gl_NumWorkGroups.x;
  const uint p = group * kResolveGroupSize + gl_LocalInvocationID.x;
  if (p >= uPixels) return;
  uint took = 0u;
  if (kDual == 0u) {
    const uint w = kPeelWords * p;
    const uvec2 c = uvec2(state[w + 2u], state[w + 3u]);
    if (c.x == 0xffffffffu && c.y == 0xffffffffu) return;
    took = state[w + 4u];
    blendLayer(w + 5u, c.y, took, false);
    const uvec2 bound = nextKey(c);
    state[w] = bound.x;
    state[w + 1u] = bound.y;
    state[w + 2u] = 0xffffffffu;
    state[w + 3u] = 0xffffffffu;
    state[w + 4u] = 0u;
  } else {
    const uint w = kDualPeelWords * p;
    const uvec2 n = uvec2(state[w + 4u], state[w + 5u]);
    if (n.x == 0xffffffffu && n.y == 0xffffffffu) return;
    const uvec2 f = uvec2(state[w + 6u], state[w + 7u]);
    took = state[w + 8u];
    blendLayer(w + 10u, n.y, took, false);
    if (n.x != f.x || n.y != f.y) {  // both sides met on one key: composited once, from the front
      blendLayer(w + 14u, f.y, state[w + 9u], true);
      took += state[w + 9u];
    }
    const uvec2 lo = nextKey(n);
    state[w] = lo.x;
    state[w + 1u] = lo.y;
    state[w + 2u] = f.x;
    state[w + 3u] = f.y;
    state[w + 4u] = 0xffffffffu;
    state[w + 5u] = 0xffffffffu;
    state[w + 6u] = 0u;
    state[w + 7u] = 0u;
    state[w + 8u] = 0u;
    state[w + 9u] = 0u;
  }
  held[p] += took;
  atomicAdd(peeled, took);
}
