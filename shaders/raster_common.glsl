// Shared part of the fragment shaders of the geometry passes, after the raster part
// (raster_exact.glsl or raster_native.glsl, which define FragmentData, rasterFragment,
// fragmentMaterial, fragmentBackFacing, fragmentUv, fragmentHasColor, fragmentColor,
// fragmentNormal and fragmentDepth): back-face culling (the native raster's; the exact raster culls
// at set-up, as the CPU engine), the alpha test, texture sampling, vertex colours and shading of the CPU engine (include/mfr/cpu/raster_frame_impl.hpp),
// operation for operation and `precise`.
uniform vec4 uRay;       // view ray of pixel (x, y): (x * ray.x + ray.y, y * ray.z + ray.w, -1)
uniform float uAmbient;  // kAmbient
uniform float uDiffuse;  // 1 - kAmbient
uniform float uInv255;   // 1.0f / 255.0f

layout(std430, binding = kBindMaterials) readonly buffer Materials {
  uint materials[];
};
layout(std430, binding = kBindColorTables) readonly buffer ColorTables {
  uint colorTables[];
};
layout(std430, binding = kBindTexels) readonly buffer Texels {
  uint texels[];
};

// n(p): the count pass adds every fragment here; so does a capture that runs without a count pass
// before it (uCountInCapture = 1: fixed k, wboit, mboit, mlab), right after the alpha test, so
// that the capture's own n(p) is the count pass's
layout(binding = kBindCounts, r32ui) uniform coherent uimageBuffer uCounts;
uniform uint uCountInCapture;

void countInCapture(FragmentData f) {
  if (uCountInCapture != 0u) imageAtomicAdd(uCounts, f.pixel, 1u);
}

float srgb8ToLinear(uint code) {
  return uintBitsToFloat(colorTables[kTableLinearBase + code]);
}

// detail::texelIndex: exact below 1e9; beyond, past the edge for clamp, else reduced over the
// wrap's period (n, 2n mirrored)
int texelIndex(float f, int n, uint wrap) {
  if (isnan(f) || isinf(f)) return 0;
  if (abs(f) < 1e9) return int(f);
  if (wrap == kTextureWrapClamp) return f < 0.0 ? -1 : n;
  const float period = float(wrap == kTextureWrapMirror ? 2 * n : n);
  precise float r = f - period * trunc(f / period);  // fmod (approximately)
  return int(r);
}

vec4 texel(uint first, int width, int x, int y) {
  const uint t = texels[first + uint(y * width + x)];
  precise float a = float(t >> 24) * uInv255;
  return vec4(srgb8ToLinear(t & 0xffu), srgb8ToLinear((t >> 8) & 0xffu),
              srgb8ToLinear((t >> 16) & 0xffu), a);
}

// detail::sampleTexture: bilinear or nearest (the flags word's kMaterialNearest), each axis wrapped
// by method_math.h's wrapTexel (the flags word's wrap S and wrap T)
vec4 sampleTexture(uint first, int width, int height, uint flags, vec2 uv) {
  const uint modeS = (flags >> kMaterialWrapSShift) & kMaterialWrapMask;
  const uint modeT = (flags >> kMaterialWrapTShift) & kMaterialWrapMask;
  if ((flags & kMaterialNearest) != 0u) {
    precise float nx = uv.x * float(width);
    precise float ny = uv.y * float(height);
    return texel(first, width, wrapTexel(texelIndex(floor(nx), width, modeS), width, modeS),
                 wrapTexel(texelIndex(floor(ny), height, modeT), height, modeT));
  }
  precise float fx = uv.x * float(width) - 0.5;
  precise float fy = uv.y * float(height) - 0.5;
  const float flx = floor(fx), fly = floor(fy);
  precise float ax = fx - flx;
  precise float ay = fy - fly;
  const int ix = texelIndex(flx, width, modeS), iy = texelIndex(fly, height, modeT);
  const int x0 = wrapTexel(ix, width, modeS), x1 = wrapTexel(ix + 1, width, modeS);
  const int y0 = wrapTexel(iy, height, modeT), y1 = wrapTexel(iy + 1, height, modeT);
  precise float oax = 1.0 - ax;
  precise float oay = 1.0 - ay;
  precise vec4 top = texel(first, width, x0, y0) * oax + texel(first, width, x1, y0) * ax;
  precise vec4 bottom = texel(first, width, x0, y1) * oax + texel(first, width, x1, y1) * ax;
  precise vec4 s = top * oay + bottom * ay;
  return s;
}

// back-face cull, alpha test and base colour (RasterFrame::surface); false when the fragment is
// discarded
bool surface(FragmentData f, bool coverageOnly, out vec4 base) {
  const uint m = fragmentMaterial() * kMaterialWords;
  const uint mode = materials[m + 7u];
  const bool needsAlphaTest = kSceneAlphaMask && mode == kAlphaMask;
  base = vec4(0.0);
  if (fragmentBackFacing() && (materials[m + kMaterialFlagsWord] & kMaterialCullBack) != 0u)
    return false;
  if (coverageOnly && !needsAlphaTest) return true;
  base = vec4(uintBitsToFloat(materials[m + 0u]), uintBitsToFloat(materials[m + 1u]),
              uintBitsToFloat(materials[m + 2u]), uintBitsToFloat(materials[m + 3u]));
  const uint texture = materials[m + 4u];
  if (kSceneTextures && texture != kNoTexture) {
    const vec2 uv = fragmentUv(f);
    precise vec4 b = base * sampleTexture(texture, int(materials[m + 5u]), int(materials[m + 6u]),
                                          materials[m + kMaterialFlagsWord], uv);
    base = b;
  }
  if (kSceneVertexColors && fragmentHasColor()) {  // the vertex colour, after the texture
    precise vec4 c = base * fragmentColor(f);
    base = c;
  }
  if (needsAlphaTest) {
    if (base.a < uintBitsToFloat(materials[m + 8u])) return false;
    base.a = 1.0;
  } else if (mode == kAlphaOpaque) {
    base.a = 1.0;
  }
  if (materials[m + 9u] != 0u) base.a = uintBitsToFloat(materials[m + 10u]);
  return true;
}

float clampUnit(float v) {  // min(max(v, 0), 1) with NaN -> 0
  const float c = v > 0.0 ? v : 0.0;
  return c < 1.0 ? c : 1.0;
}

// encodeSrgb8 by the CPU engine's tables: its bucket's smallest code, one up where c reaches the
// next code's lower bound (at most one code boundary lies in a bucket: ColorTables, and the test
// Color.BucketGuessIsAtMostOneBelowEveryInputOfItsBucket)
uint encodeSrgb8(float c) {
  precise float scaled = c * 4095.0 + 0.5;
  const uint entry = kTableEncodeBase + 2u * uint(int(scaled));
  const uint code = colorTables[entry];
  return c >= uintBitsToFloat(colorTables[entry + 1u]) ? code + 1u : code;
}

// packFragmentColor
uint packColor(vec3 rgb, float alpha) {
  const float a = clampUnit(alpha);
  precise float scaledA = a * 255.0 + 0.5;
  return encodeSrgb8(clampUnit(rgb.r)) | (encodeSrgb8(clampUnit(rgb.g)) << 8) |
         (encodeSrgb8(clampUnit(rgb.b)) << 16) | (uint(int(scaledA)) << 24);
}

// overNodeWord: an over word's alpha byte 0 -> the word 0 (the additive node of no emission),
// 1 -> 2 (1 is the multiply node's byte)
uint overNodeWord(uint word) {
  const uint a8 = word >> 24;
  if (a8 == kAdditiveNode) return 0u;
  if (a8 == kMultiplyNode) return (word & 0x00ffffffu) | (2u << 24);
  return word;
}

// packBlendedColor: the node word of the material's blend mode (mfr::BlendMode); only the scene's
// modes are compiled in (kSceneBlendModes)
uint packBlended(uint mode, vec3 rgb, float alpha) {
  if (kSceneBlendModes == (1u << kBlendOver)) return overNodeWord(packColor(rgb, alpha));
  const float a = clampUnit(alpha);
  if ((kSceneBlendModes & (1u << kBlendPremultiplied)) != 0u && mode == kBlendPremultiplied) {
    precise float scaledA = a * 255.0 + 0.5;
    if (int(scaledA) == 0) return packColor(rgb, 0.0) & 0x00ffffffu;
    precise vec3 straight = rgb / a;
    return overNodeWord(packColor(straight, a));
  }
  if ((kSceneBlendModes & (1u << kBlendAdditive)) != 0u && mode == kBlendAdditive) {
    precise vec3 emission = rgb * a;
    return packColor(emission, 0.0) & 0x00ffffffu;
  }
  if ((kSceneBlendModes & (1u << kBlendMultiply)) != 0u && mode == kBlendMultiply) {
    precise vec3 factor = (1.0 - a) + a * rgb;
    return (packColor(factor, 0.0) & 0x00ffffffu) | (kMultiplyNode << 24);
  }
  return overNodeWord(packColor(rgb, alpha));
}

// headlight shading (RasterFrame::shade): the colour word, and the clamped n.v it used
uint shadeWithCosine(FragmentData f, vec4 base, out float cosine) {
  const vec3 n = fragmentNormal(f);
  const float nx = n.x, ny = n.y, nz = n.z;
  precise float dx = f.pos.x * uRay.x + uRay.y;
  precise float dy = f.pos.y * uRay.z + uRay.w;
  precise float nn = (nx * nx + ny * ny + nz * nz) * (dx * dx + dy * dy + 1.0);
  precise float num = nz - nx * dx - ny * dy;
  precise float root = sqrt(nn);
  precise float q = num / root;
  const float ndotv = nn > 0.0 ? (q < -1.0 ? -1.0 : (1.0 < q ? 1.0 : q)) : 1.0;
  precise float light = uAmbient + uDiffuse * abs(ndotv);
  precise vec3 rgb = base.rgb * light;
  cosine = ndotv;
  const uint flags = materials[fragmentMaterial() * kMaterialWords + kMaterialFlagsWord];
  return packBlended((flags >> kMaterialBlendShift) & kMaterialBlendMask, rgb, base.a);
}

uint shade(FragmentData f, vec4 base) {
  float cosine;
  return shadeWithCosine(f, base, cosine);
}

// occupancy map bucket of depth z (mfr::OccupancyMap::bucket): monotone in z, shared by the fill
// pass and the capture's test
uint occupancyBucket(float z, float zn, float zf, uint buckets) {
  if (!(zf > zn)) return 0u;
  precise float num = z - zn;
  precise float den = zf - zn;
  precise float q = num / den;
  precise float t = q * float(buckets);
  const uint b = t > 0.0 ? uint(t) : 0u;
  return b < buckets ? b : buckets - 1u;
}
