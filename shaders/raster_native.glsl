// The native raster of the geometry passes (--gl-raster native, the default; prepended before
// raster_common.glsl with raster_native.vert): GL's own clipper, rasterizer (its fill rule and
// sub-pixel precision) and perspective-correct interpolation, in single precision, no geometry
// shader. This is the part an engine replaces with its own vertex outputs: a fragment is the
// pixel GL shades, its depth gl_FragCoord.z, its normal, uv and colour the interpolated varyings, its
// material the triangle's (gl_PrimitiveID indexes the draw's triangles).
//
// Multisampling (--samples S > 1, core/samples.hpp): the framebuffer has S samples, whose
// positions GlEngine::create checked to be the standard pattern (uSampleOffsets). GL runs this
// shader once per pixel and triangle with the covered samples in gl_SampleMaskIn (per-pixel
// storage: the fragment is evaluated at its first covered sample and carries the mask in its
// depth's low bits, method_math.h's withCoverageBits), or, with sample shading at rate 1, once per
// covered sample (per-sample storage: the fragment is the sample's, stored at storage pixel
// (x S + s, y) of the W S x H storage).
in vec3 vNormal;  // view space
in vec2 vUv;
in vec4 vColor;  // perspective-correct vertex colour
in vec2 vClipZW;  // clip z and w: window depth at a sample as z / w (interpolateAtSample)

uniform vec2 uSampleOffsets[kMaxSampleSums];  // each sample's offset from the centre, in pixels
uniform ivec2 uSize;

layout(std430, binding = kBindTriMaterial) readonly buffer TriMaterial {
  uint triMaterial[];
};

struct FragmentData {
  ivec2 px;   // storage pixel, rows top to bottom (raster_native.vert flips y)
  int pixel;  // px.y * storage width + px.x
  vec2 pos;   // where the fragment is evaluated, in pixels (the image pixel's index at its centre)
  int sampleIndex;  // multisampled: the sample it is evaluated at
  uint coverage;  // multisampled: the covered samples (per-pixel storage)
};

// every fragment GL generates is covered (at one sample at least)
bool rasterFragment(out FragmentData f) {
  const ivec2 px = ivec2(gl_FragCoord.xy);
  f.px = px;
  f.pos = vec2(px);
  f.sampleIndex = 0;
  f.coverage = 1u;
  if (kViewSamples > 1) {
    f.coverage = uint(gl_SampleMaskIn[0]) & sampleBits(kViewSamples);
    if (f.coverage == 0u) return false;
    f.sampleIndex = findLSB(f.coverage);  // per-sample shading: the one bit of the invocation's sample
    f.pos = vec2(px) + uSampleOffsets[f.sampleIndex];
    if (kViewSampleStorage) f.px = ivec2(px.x * kViewSamples + f.sampleIndex, px.y);
  }
  f.pixel = f.px.y * uSize.x + f.px.x;
  return true;
}

uint fragmentMaterial() {
  return triMaterial[gl_PrimitiveID];
}

// raster_native.vert negates y, which mirrors every triangle: a front face (counter-clockwise in
// the scene's own projection) reaches GL clockwise, so GL's front-facing (glFrontFace GL_CCW) is
// the scene's back face
bool fragmentBackFacing() {
  return gl_FrontFacing;
}

vec2 fragmentUv(FragmentData f) {
  return kViewSamples > 1 ? interpolateAtSample(vUv, f.sampleIndex) : vUv;
}

vec3 fragmentNormal(FragmentData f) {
  return kViewSamples > 1 ? interpolateAtSample(vNormal, f.sampleIndex) : vNormal;
}

// vertex colours: every triangle of a scene that has them (kSceneVertexColors: GL's
// interpolation of an all-white triangle is white up to rounding; the exact raster decides per
// triangle, as the CPU engine)
bool fragmentHasColor() {
  return true;
}

vec4 fragmentColor(FragmentData f) {
  return kViewSamples > 1 ? interpolateAtSample(vColor, f.sampleIndex) : vColor;
}

// window depth (glDepthRange 0..1: z_ndc / 2 + 1/2), clamped to [0, 1] as the exact raster does;
// multisampled: at the fragment's sample (z / w of the perspective-correct clip z and w), with
// per-pixel storage's coverage mask in the low bits
float fragmentDepth(FragmentData f) {
  if (kViewSamples <= 1) return clamp(gl_FragCoord.z, 0.0, 1.0);
  const vec2 zw = interpolateAtSample(vClipZW, f.sampleIndex);
  precise float z = zw.x / zw.y * 0.5 + 0.5;
  const float depth = clamp(z, 0.0, 1.0);
  if (kViewSampleStorage) return depth;
  return uintBitsToFloat(withCoverageBits(floatBitsToUint(depth), f.coverage, kViewSamples));
}

// the share of the pixel's samples a node covers (per-pixel storage: its mask's samples over
// the pixel's, which weights it in the hybrid tail); 1 otherwise
float coverageShare(uint depthBits) {
  if (kViewSamples <= 1 || kViewSampleStorage) return 1.0;
  return float(bitCount(depthBits & sampleBits(kViewSamples))) / float(kViewSamples);
}

// the scene triangle's index (the draw's triangles are the scene's, in order)
uint fragmentPrimitive() {
  return uint(gl_PrimitiveID);
}
