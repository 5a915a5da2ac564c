// Layout shared by the C++ side of the OpenGL engine and its GLSL shaders (the shader embedding
// step prepends this file to every shader, after the #version line), so the engines cannot drift:
// the 8-byte fragment node, the lock values, the binding points and the work-group sizes.
//
// Node: two uints in GLSL (uvec2), x = hi = floatBitsToUint(depth), y = lo = RGBA8 colour word
// (mfr::packFragmentColor). Depths are in [0, 1], so comparing (hi, lo) lexicographically as
// unsigned integers is the unsigned 64-bit order of mfr::FragmentNode: (depth, colour).
#ifdef __cplusplus
#pragma once
#include <cstdint>
namespace mfr::gl {
using uint = uint32_t;
#define MFR_GL_CONST(type, name, value) inline constexpr type name = value;
#else
#define MFR_GL_CONST(type, name, value) const type name = value;
#endif

MFR_GL_CONST(uint, kNodeWords, 2u)              // uints per node
MFR_GL_CONST(uint, kNodeBytes, 8u)              // bytes per node
MFR_GL_CONST(uint, kNodeHiIndex, 0u)            // uvec2 component holding the depth bits
MFR_GL_CONST(uint, kFarDepthBits, 0x7f800000u)  // +inf: the empty node (mfr::kFarNode)
MFR_GL_CONST(uint, kLockFree, 0u)               // per-pixel spin-lock values
MFR_GL_CONST(uint, kLockHeld, 1u)
MFR_GL_CONST(uint, kStoreMaxArray, 0u)  // k-buffer stores (MFR_STORE, alloc_pack's uStore)
MFR_GL_CONST(uint, kStoreMaxHeap, 1u)
// occupancy per pixel: zn bits, zf bits, j_k (the k-th occupied bucket)
MFR_GL_CONST(uint, kOccupancyWords, 3u)
// hybrid tail per pixel (mfr::HybridTail): sum of a * r, a * g, a * b, sum of a (float bits), t
MFR_GL_CONST(uint, kTailWords, 5u)
MFR_GL_CONST(uint, kOccupancyNoCulling, 0xffffffffu)  // mfr::OccupancyMap::kNoCulling
MFR_GL_CONST(uint, kScanGroupSize, 256u)              // prefix sum: threads per work group
MFR_GL_CONST(uint, kScanItemsPerThread, 4u)           // consecutive elements per thread
MFR_GL_CONST(uint, kResolveGroupSize, 64u)            // resolve: pixels per work group
MFR_GL_CONST(uint, kResolveLocalNodes, 128u)          // resolve: nodes sorted in a local array
MFR_GL_CONST(uint, kMaxClipVertices, 12u)             // Sutherland-Hodgman polygon capacity
// raster.geom's gTopLeft: bits 0-2 the edges' top-left flags, this bit the triangle's vertex
// colours (mfr::Scene::hasVertexColor, mfr::TriangleSetup::hasColor)
MFR_GL_CONST(uint, kTopLeftHasColor, 8u)

// binding points: SSBOs (at most 8, GL 4.3's minimum of bindings) and image units (2)
MFR_GL_CONST(uint, kBindCounts, 0u)        // n(p): r32ui imageBuffer unit (count), SSBO (resolve)
MFR_GL_CONST(uint, kBindOffsets, 1u)       // exclusive prefix sum of n(p)
MFR_GL_CONST(uint, kBindNodes, 2u)         // uvec2 nodes
MFR_GL_CONST(uint, kBindFill, 3u)          // A-buffer per-pixel fill counters
MFR_GL_CONST(uint, kBindImage, 3u)         // resolve output: linear RGB floats (resolve only)
MFR_GL_CONST(uint, kBindMaterials, 4u)     // materials
MFR_GL_CONST(uint, kBindTriMaterial, 5u)   // material index per triangle
MFR_GL_CONST(uint, kBindColorTables, 6u)   // srgb8ToLinear, coarseSrgb8, lowerBound
MFR_GL_CONST(uint, kBindTexels, 7u)        // every texture's RGBA8 texels, one uint each
MFR_GL_CONST(uint, kBindLocks, 1u)         // r32ui imageBuffer unit of the spin-locks
MFR_GL_CONST(uint, kBindOccupancy, 0u)     // occupancy: kOccupancyWords per pixel
MFR_GL_CONST(uint, kBindTails, 1u)         // hybrid tails (k-buffer capture)
MFR_GL_CONST(uint, kBindResolveTails, 4u)  // hybrid tails (resolve)
MFR_GL_CONST(uint, kBindOccBits, 3u)       // occupancy: bitmaps (fill and count passes)
MFR_GL_CONST(uint, kBindCaptureStats, 3u)  // k-buffer capture: culled counters
MFR_GL_CONST(uint, kBindScanIn, 0u)        // prefix sum level: input, output, block sums
MFR_GL_CONST(uint, kBindScanOut, 1u)
MFR_GL_CONST(uint, kBindScanSums, 2u)
// per-pixel allocation (variable k): usamplerBuffer (rg32ui) on this texture unit, per pixel
// (first slot, k(p) | kAllocHeapBit when the pixel's store is the max-heap)
MFR_GL_CONST(uint, kBindAllocation, 0u)
MFR_GL_CONST(uint, kAllocHeapBit, 0x80000000u)
// nearest |n.v| pass: per pixel the nearest node (depth bits, colour) and unorm8(|n.v|)
MFR_GL_CONST(uint, kNearestWords, 3u)
MFR_GL_CONST(uint, kBindNearest, 0u)
// weighted blended OIT: per pixel sum C w (r, g, b), sum a w, revealage (mfr::WboitPixel)
MFR_GL_CONST(uint, kWboitWords, 5u)
MFR_GL_CONST(uint, kBindAccum, 2u)
// moment-based OIT: per pixel b0, b1..bN, then sum T a c (r, g, b), sum T a (mfr::MboitPixel,
// mfr::PowerMomentPixel, mfr::TrigMomentPixel): kMboitWords with N = 4, kMboitWordsBase + N for
// N = 6, 8; with 16-bit moments (mfr::QuantizedMomentPixel) kMboitWordsBase + N / 2
MFR_GL_CONST(uint, kMboitWords, 9u)
MFR_GL_CONST(uint, kMboitWordsBase, 5u)
// adaptive transparency: per pixel N nodes of (depth, transmittance), then sum vis a c (r, g, b)
// (mfr::AoitPixel<N>): kAoitNodeWords N + kAoitColorWords words, N = 4, 8 or 16
MFR_GL_CONST(uint, kAoitNodeWords, 2u)
MFR_GL_CONST(uint, kAoitColorWords, 3u)
// deep and fast approximate OIT: per pixel sum a c (r, g, b), sum a, sum a z, sum a c z (r, g, b),
// T, n, farthest depth, nearest depth bits, nearest RGBA8 (mfr::DfaoitPixel); the resolve's
// network weights (mfr::dfaoitWeights)
MFR_GL_CONST(uint, kDfaoitWords, 13u)
// stochastic transparency per pixel (mfr::StochasticPixel<8>): 8 sample depths (float bits), T,
// sum vis a c (r, g, b), sum vis a
MFR_GL_CONST(int, kStochasticSamples, 8)
MFR_GL_CONST(uint, kStochasticWords, 13u)
// hashed alpha per pixel (mfr::HashedAlphaPixel): the nearest kept depth (float bits), its colour
MFR_GL_CONST(uint, kHashedAlphaWords, 2u)
MFR_GL_CONST(uint, kBindDfaoitWeights, 1u)
// multi-layer alpha blending: per node depth, premultiplied r, g, b, transmittance (mfr::MlabNode)
MFR_GL_CONST(uint, kMlabWords, 5u)
// depth peeling: per pixel bound, candidate key, multiplicity, front r, g, b, T (mfr::PeelPixel);
// dual depth peeling: lo, hi, nearest and farthest keys, their multiplicities, front and back
// r, g, b, T (mfr::DualPeelPixel); peel.frag lists the words
MFR_GL_CONST(uint, kPeelWords, 9u)
MFR_GL_CONST(uint, kDualPeelWords, 18u)
// deep k-buffer: feature accumulators per pixel (n, nearest depth bits and colour, farthest depth
// bits, premultiplied colour sum r, g, b), the network's weights, the importance
MFR_GL_CONST(uint, kDkbAccWords, 7u)
MFR_GL_CONST(uint, kBindDkbAcc, 0u)
MFR_GL_CONST(uint, kBindDkbWeights, 1u)
MFR_GL_CONST(uint, kBindDkbImportance, 2u)
MFR_GL_CONST(uint, kBindImage2, 4u)  // mlab resolve output (kBindImage is mlab's fill counts)
// per-pixel linked lists (mfr::LinkedNode): a node is depth bits, RGBA8, next index; a head word
// per pixel (kListEnd: empty); the pool counter; in the resolve, each list's length per pixel
MFR_GL_CONST(uint, kListNodeWords, 3u)
MFR_GL_CONST(uint, kListEnd, 0xffffffffu)  // mfr::kListEnd
MFR_GL_CONST(uint, kBindListHeads, 0u)     // heads (capture and resolve)
MFR_GL_CONST(uint, kBindListLengths, 1u)   // resolve: the nodes each list holds

// variable-k allocation in compute shaders (alloc_histogram.comp, importance.comp,
// importance_total.comp, alloc_k.comp, alloc_pack.comp)
MFR_GL_CONST(uint, kAllocHistogramBins, 1024u)  // mfr::kHistogramBins
MFR_GL_CONST(uint, kAllocSummaryWords, 1025u)   // the histogram of n(p), then max n(p)
MFR_GL_CONST(uint, kAllocTotalWords, 4u)        // sum of k(p) materialised, as allocated (lo, hi)
MFR_GL_CONST(uint, kAllocCapped, 0u)            // alloc_k.comp: k(p) = min(n(p), k)
MFR_GL_CONST(uint, kAllocByImportance, 1u)      // alloc_k.comp: k(p) = floor(I(p) / I_tot F(M))
MFR_GL_CONST(uint, kImportanceWords, 5u)        // per pixel I, I_d, I_per, I_f, noise (floats)
MFR_GL_CONST(uint, kTotalChunk, 32768u)         // importance_total.comp: pixels per dispatch
MFR_GL_CONST(uint, kCosineNone, 0u)             // importance.comp: |n.v| source
MFR_GL_CONST(uint, kCosineNearest, 1u)          // the nearest pass's unorm8 (kNearestWords)
MFR_GL_CONST(uint, kCosineFloats, 2u)           // a previous frame's floats
MFR_GL_CONST(uint, kBindAllocCounts, 0u)        // n(p)
MFR_GL_CONST(uint, kBindAllocSummary, 1u)       // histogram (alloc_histogram), totals (alloc_k)
MFR_GL_CONST(uint, kBindAllocK, 2u)             // k(p) materialised: min(k(p), n(p))
MFR_GL_CONST(uint, kBindAllocReserved, 3u)      // k(p) as allocated (alloc_k)
MFR_GL_CONST(uint, kBindAllocWords, 3u)         // (first slot, k(p) | heap bit) (alloc_pack)
MFR_GL_CONST(uint, kBindImportance, 4u)         // kImportanceWords per pixel
MFR_GL_CONST(uint, kBindImportanceTotal, 5u)    // I_tot (double)
MFR_GL_CONST(uint, kBindCosine, 6u)             // |n.v| (kCosineNearest or kCosineFloats)
MFR_GL_CONST(uint, kBindAllocOffsets, 7u)       // exclusive prefix sum of k(p) (alloc_pack)

// material record (12 uint words; floats as their bits): base colour R, G, B, A; the texture's
// first texel in the texel buffer (kNoTexture: none), its width, height; alpha mode
// (mfr::AlphaMode); cutoff; alpha override flag, override value; flags (kMaterialCullBack, the
// texture's sampler: wrap S and wrap T as method_math.h's kTextureWrap* in 2 bits each at
// kMaterialWrapSShift and kMaterialWrapTShift, kMaterialNearest, the blend mode at
// kMaterialBlendShift)
MFR_GL_CONST(uint, kMaterialWords, 12u)
MFR_GL_CONST(uint, kMaterialFlagsWord, 11u)
MFR_GL_CONST(uint, kMaterialCullBack, 1u)    // flag: back faces culled (mfr::Scene::cullsBackFaces)
MFR_GL_CONST(uint, kMaterialWrapSShift, 1u)  // mfr::TextureSampler::wrapS
MFR_GL_CONST(uint, kMaterialWrapTShift, 3u)  // mfr::TextureSampler::wrapT
MFR_GL_CONST(uint, kMaterialWrapMask, 3u)
MFR_GL_CONST(uint, kMaterialNearest, 32u)    // flag: TextureFilter::Nearest (else bilinear)
MFR_GL_CONST(uint, kMaterialBlendShift, 6u)  // mfr::BlendMode in 2 bits (packBlended)
MFR_GL_CONST(uint, kMaterialBlendMask, 3u)
MFR_GL_CONST(uint, kBlendOver, 0u)  // mfr::BlendMode values
MFR_GL_CONST(uint, kBlendPremultiplied, 1u)
MFR_GL_CONST(uint, kBlendAdditive, 2u)
MFR_GL_CONST(uint, kBlendMultiply, 3u)
MFR_GL_CONST(uint, kNoTexture, 0xffffffffu)
MFR_GL_CONST(uint, kAlphaOpaque, 0u)  // mfr::AlphaMode values
MFR_GL_CONST(uint, kAlphaMask, 1u)
// colour tables (std430 uint words): 256 floats (bits) of srgb8ToLinear, then per encode bucket
// b = int(c * 4095 + 0.5) two words: the code of the bucket's smallest input
// (ColorTables::bucketLowSrgb8) and the float bits of the next code's lower bound (lowerBound), so
// the encode is one lookup and one upward correction
MFR_GL_CONST(uint, kTableLinearBase, 0u)
MFR_GL_CONST(uint, kTableEncodeBase, 256u)
MFR_GL_CONST(uint, kTableWords, 8448u)

// Bindings per shader file: the kBind* points each file declares (SSBO unless marked; image:
// an imageBuffer unit, texture: a texture unit). A raster program also has its raster part's
// and raster_common.glsl's; the GL engine binds what a pass reads before its draw or dispatch.
// GlShaders.BindingsListedPerShader checks this list against the shaders.
//   capture_abuffer.frag: kBindOffsets kBindNodes kBindFill
//   capture_kbuffer.frag: kBindNodes kBindLocks(image) kBindAllocation(texture) kBindOccupancy
//       kBindTails kBindCaptureStats
//   capture_kbuffer_atomic64.frag: kBindNodes kBindCaptureStats
//   count.frag: -
//   depth_range.frag: kBindOccupancy
//   dkb_features.frag: kBindDkbAcc kBindLocks(image)
//   mboit_color.frag: kBindAccum kBindLocks(image)
//   mboit_moments.frag: kBindAccum kBindLocks(image)
//   mlab.frag: kBindNodes kBindFill kBindLocks(image)
//   aoit_visibility.frag: kBindAccum kBindLocks(image)
//   aoit_color.frag: kBindAccum kBindLocks(image)
//   nearest_cosine.frag: kBindNearest kBindLocks(image)
//   occupancy_fill.frag: kBindOccupancy kBindOccBits
//   wboit.frag: kBindAccum kBindLocks(image)
//   dfaoit.frag: kBindAccum kBindLocks(image)
//   stochastic.frag: kBindAccum kBindLocks(image)
//   hashed_alpha.frag: kBindAccum kBindLocks(image)
//   peel.frag: kBindAccum kBindCaptureStats kBindTails kBindLocks(image)
//   alloc_histogram.comp: kBindAllocCounts kBindAllocSummary
//   alloc_k.comp: kBindAllocCounts kBindAllocSummary kBindAllocK kBindAllocReserved kBindImportance
//       kBindImportanceTotal
//   alloc_pack.comp: kBindAllocCounts kBindAllocK kBindAllocOffsets kBindAllocWords
//   dkb_infer.comp: kBindDkbAcc kBindDkbWeights kBindDkbImportance kBindColorTables
//   importance.comp: kBindAllocCounts kBindImportance kBindCosine
//   importance_total.comp: kBindImportance kBindImportanceTotal
//   mboit_resolve.comp: kBindAccum kBindImage
//   mlab_resolve.comp: kBindNodes kBindFill kBindImage2
//   aoit_resolve.comp: kBindAccum kBindImage
//   occupancy_count.comp: kBindOccBits kBindOccupancy kBindAllocation(texture)
//   prefix_sum.comp: kBindScanIn kBindScanOut kBindScanSums
//   prefix_sum_add.comp: kBindScanOut kBindScanSums
//   resolve.comp: kBindCounts kBindOffsets kBindNodes kBindImage kBindColorTables kBindResolveTails
//       kBindAllocation(texture)
//   swap_node_words.comp: kBindNodes
//   wboit_resolve.comp: kBindAccum kBindImage
//   dfaoit_resolve.comp: kBindAccum kBindDfaoitWeights kBindImage kBindColorTables
//   stochastic_resolve.comp: kBindAccum kBindImage
//   hashed_alpha_resolve.comp: kBindAccum kBindImage kBindColorTables
//   peel_step.comp: kBindAccum kBindCaptureStats kBindOffsets kBindColorTables
//   peel_resolve.comp: kBindAccum kBindResolveTails kBindImage
//   raster_common.glsl: kBindMaterials kBindColorTables kBindTexels kBindCounts(image)
//   raster_native.glsl: kBindTriMaterial
//   raster.geom: kBindTriMaterial kBindMaterials
//   capture_list.frag: kBindListHeads kBindNodes kBindFill kBindTails
//   resolve_list.comp: kBindListHeads kBindListLengths kBindNodes kBindImage kBindColorTables
//       kBindResolveTails
// (end of the bindings per shader file)

// the k-buffer capture's culled counters (kBindCaptureStats): kCaptureStatSlots slots of
// kCaptureStatStride words (a 64-byte cache line each), word 0 the occupancy test's, word 1 the
// k+ test's; a fragment adds to its 64x64 tile's slot, so rasterizer threads working on
// different tiles seldom contend for one line (on llvmpipe a single counter cost 15 ms of a
// 300 ms capture); the host sums the slots
MFR_GL_CONST(uint, kCaptureStatSlots, 16u)
MFR_GL_CONST(uint, kCaptureStatStride, 16u)

// resolve.comp's node layouts (its MFR_RESOLVE_NODES switch)
MFR_GL_CONST(uint, kResolveFixedK, 0u)    // k slots at p * k
MFR_GL_CONST(uint, kResolveABuffer, 1u)   // n(p) nodes at offsets[p]
MFR_GL_CONST(uint, kResolvePerPixel, 2u)  // k(p) slots from the allocation's first slot

#ifdef __cplusplus
}  // namespace mfr::gl
#else
// The engine's compile-time switches, the same in every program of one engine (GlEngine::create
// puts the #defines before this file: gl_programs.hpp's EngineSwitches): the view's sampling and
// which material features the scene has. Shaders branch on these constants, so the compiler
// removes the paths a view cannot take; a branch on a uniform would run both sides on a SIMD
// rasterizer such as llvmpipe (masked) and keep every path's registers on a GPU. The defaults
// (one sample, every feature) are what a shader lifted without the engine gets.
#ifndef MFR_SAMPLES
#define MFR_SAMPLES 1  // samples per pixel (core/samples.hpp)
#endif
#ifndef MFR_SAMPLE_STORAGE
#define MFR_SAMPLE_STORAGE 0  // multisampled: 1 per-sample storage, 0 per-pixel with masks
#endif
#ifndef MFR_VERTEX_COLORS
#define MFR_VERTEX_COLORS 1  // the scene has vertex colours
#endif
#ifndef MFR_TEXTURES
#define MFR_TEXTURES 1  // some material has a base colour texture
#endif
#ifndef MFR_ALPHA_MASK
#define MFR_ALPHA_MASK 1  // some material is alpha-tested (kAlphaMask)
#endif
#ifndef MFR_BLEND_MODES
#define MFR_BLEND_MODES 15u  // bit 1 << mfr::BlendMode for each blend mode of the scene
#endif
const int kViewSamples = MFR_SAMPLES;
const bool kViewSampleStorage = MFR_SAMPLES > 1 && MFR_SAMPLE_STORAGE != 0;
// per-pixel multisampled storage: the samples of the nodes' coverage masks (1 otherwise)
const int kViewMaskSamples = kViewSampleStorage ? 1 : kViewSamples;
const bool kSceneVertexColors = MFR_VERTEX_COLORS != 0;
const bool kSceneTextures = MFR_TEXTURES != 0;
const bool kSceneAlphaMask = MFR_ALPHA_MASK != 0;
const uint kSceneBlendModes = MFR_BLEND_MODES;

// the first word of the k-buffer capture's culled counters for a fragment at storage pixel px
// (kCaptureStatSlots)
uint captureStatSlot(ivec2 px) {
  return (((uint(px.y) >> 6) * 5u + (uint(px.x) >> 6)) % kCaptureStatSlots) * kCaptureStatStride;
}

// a < b in the node order (unsigned 64-bit (hi, lo))
bool nodeLess(uvec2 a, uvec2 b) {
  return a.x < b.x || (a.x == b.x && a.y < b.y);
}
#endif
