// One frame of the GL engine: the plan of a method's technique (GlEngine::State::planRender),
// then its passes in order (FrameRun: allocation, n(p), capture, resolve, read-back), each phase
// one switch over the technique (mfr/gl/gl_technique.hpp).
#include <epoxy/gl.h>

#include <algorithm>
#include <array>
#include <bit>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "gl/gl_state.hpp"
#include "mfr/gl/gl_engine.hpp"
#include "mfr/gl/gl_technique.hpp"
#include "mfr/gl/shared_layout.h"
#include "mfr/method/aoit.hpp"
#include "mfr/method/dfaoit.hpp"
#include "mfr/method/hashed_alpha.hpp"
#include "mfr/method/mboit.hpp"
#include "mfr/method/method_math.h"
#include "mfr/method/pass_plan.hpp"
#include "mfr/method/stochastic.hpp"
#include "mfr/scene/camera.hpp"

namespace mfr::gl {
namespace {

static_assert(kStochasticSamples == Stochastic8Method::kSamples &&
              kStochasticSamples == StochasticStrat8Method::kSamples &&
              kStochasticWords * 4 == sizeof(StochasticPixel<kStochasticSamples>));
static_assert(kHashedAlphaWords * 4 == sizeof(HashedAlphaPixel));

// n(p) before the capture: the A-buffer sizes its slots by it; the others count n(p) in their
// capture when no count came before (no pass of its own)
bool countPassFirst(GlTechnique t) {
  switch (t) {
    case GlTechnique::ABuffer:
      return true;
    case GlTechnique::KBuffer:
    case GlTechnique::Wboit:
    case GlTechnique::Mboit:
    case GlTechnique::Mlab:
    case GlTechnique::Aoit:
    case GlTechnique::LinkedList:
    case GlTechnique::Peel:
    case GlTechnique::Dfaoit:
    case GlTechnique::Stochastic:
    case GlTechnique::HashedAlpha:
      return false;
  }
  return false;
}

// whether the technique's nodes are fragment nodes (depth, colour) that readNodes returns
bool fragmentNodes(GlTechnique t) {
  switch (t) {
    case GlTechnique::ABuffer:
    case GlTechnique::KBuffer:
      return true;
    case GlTechnique::Wboit:
    case GlTechnique::Mboit:
    case GlTechnique::Mlab:        // (mlab's nodes are merged layers, not fragments)
    case GlTechnique::Aoit:        // (aoit's are visibility steps)
    case GlTechnique::LinkedList:  // (read by walking the lists: readLists)
    case GlTechnique::Peel:
    case GlTechnique::Dfaoit:
    case GlTechnique::Stochastic:
    case GlTechnique::HashedAlpha:
      return false;
  }
  return false;
}

// the moment technique's floats per pixel: b0, N moments, four accumulators (shared_layout.h)
uint32_t mboitMomentWords(const MethodDesc& m) {
  const auto n = static_cast<uint32_t>(mboitMomentCount(m.compositing));
  return mboitQuantized(m.compositing) ? n / 2 : n;  // 16-bit codes: two per word
}
uint32_t mboitWords(const MethodDesc& m) {
  return kMboitWordsBase + mboitMomentWords(m);
}

// the AOIT technique's floats per pixel: N nodes of (depth, transmittance), the colour sum
uint32_t aoitWords(const MethodDesc& m) {
  return kAoitNodeWords * static_cast<uint32_t>(aoitNodeCount(m.compositing)) + kAoitColorWords;
}

// depth peeling's words per pixel (peel.frag)
uint32_t peelWords(const MethodDesc& m) {
  return m.compositing == Compositing::DualPeel ? kDualPeelWords : kPeelWords;
}

// bytes per pixel of the frame's largest per-pixel buffer (each must fit one storage block)
uint64_t largestPerPixelBytes(const RenderPlan& p) {
  const uint64_t occupancy = static_cast<uint64_t>(std::max(p.method.occupancyWords, 0)) * 4;
  switch (p.technique) {
    case GlTechnique::ABuffer:
      return 12;  // the image (the nodes are checked on their own)
    case GlTechnique::KBuffer:
      return std::max<uint64_t>({12, p.hybrid ? kTailWords * 4 : 0,
                                 p.perPixel ? 8 : uint64_t{p.k} * kNodeBytes, occupancy});
    case GlTechnique::Wboit:
      return std::max<uint64_t>(12, kWboitWords * 4);
    case GlTechnique::Mboit:
      return std::max<uint64_t>(12, mboitWords(p.method) * 4);
    case GlTechnique::Mlab:
      return std::max<uint64_t>(12, uint64_t{p.k} * kMlabWords * 4);
    case GlTechnique::Aoit:
      return std::max<uint64_t>(12, aoitWords(p.method) * 4);
    case GlTechnique::LinkedList:
      return std::max<uint64_t>(12, p.hybrid ? kTailWords * 4 : 0);
    case GlTechnique::Peel:
      return std::max<uint64_t>({12, peelWords(p.method) * 4, p.hybrid ? kTailWords * 4 : 0});
    case GlTechnique::Dfaoit:
      return std::max<uint64_t>(12, kDfaoitWords * 4);
    case GlTechnique::Stochastic:
      return std::max<uint64_t>(12, kStochasticWords * 4);
    case GlTechnique::HashedAlpha:
      return std::max<uint64_t>(12, kHashedAlphaWords * 4);
  }
  return 12;
}

}  // namespace

// One run of render(): the frame's buffers (freed with it), the passes in order and the read-back.
struct GlEngine::State::FrameRun {
  State& s;
  const RenderPlan& plan;
  GlRenderOutput& out;
  FrameBuffers fb;
  GLuint counts = 0, offsets = 0, nodes = 0, tails = 0, accum = 0, image = 0, heads = 0, peeled = 0;
  uint64_t nodeCount = 0;
  bool countInCapture = false;  // the capture adds n(p) (no count pass ran)

  // program `id` with its switches `defines` (Programs::variant); 0 and the frame's failure when
  // it does not link
  GLuint variant(ProgramId id, const std::string& defines) {
    auto p = s.programs.variant(id, defines);
    if (p) return *p;
    if (!fb.failure) fb.failure = p.error();
    return 0;
  }

  // a capture program: whether it counts n(p), and the counts' image unit
  void useCapture(GLuint program) {
    glUseProgram(program);
    glProgramUniform1ui(program, loc(program, "uCountInCapture"), countInCapture ? 1u : 0u);
    fb.bindImage(counts, kBindCounts);
  }

  // the per-pixel accumulators (accum), every pixel starting as the words `pixel`, and the
  // pixels' spin-locks, free; returns the locks
  GLuint makeAccumulators(std::span<const uint32_t> pixel) {
    const uint64_t pixels = plan.pixels;
    std::vector<uint32_t> init(pixels * pixel.size());
    for (uint64_t p = 0; p < pixels; ++p)
      std::copy(pixel.begin(), pixel.end(),
                init.begin() + static_cast<ptrdiff_t>(p * pixel.size()));
    accum = fb.make("accumulators", init.size() * 4, init.data());
    const GLuint locks = fb.make("locks", pixels * 4);
    clearUint(locks, kLockFree);
    return locks;
  }

  FrameRun(State& state, const RenderPlan& p, GlRenderOutput& output)
      : s(state), plan(p), out(output), fb(&output.bufferBytes, &state.framePool) {}

  // one timed pass: GL's elapsed time and the wall time around it
  template <class Body>
  void pass(const char* name, Body&& body) {
    if (fb.failure) return;  // a buffer GL could not allocate: reported below
    timedGpuPass(s.query, out.passes, name, body);
  }

  // the per-pixel allocation: (first slot, k(p) | heap bit), a texel buffer
  void bindAllocation() {
    const Allocation* alloc = plan.alloc;
    const uint32_t pixels = plan.pixels;
    const bool device = plan.device;
    const bool perPixel = plan.perPixel;
    if (device) {
      out.bufferBytes["allocation"] += uint64_t{pixels} * 8;
      fb.bindTexture(s.deviceWords, GL_RG32UI, kBindAllocation);
    } else if (perPixel) {
      std::vector<uint32_t> words(uint64_t{pixels} * 2);
      for (uint32_t p = 0; p < pixels; ++p) {
        words[2 * p] = static_cast<uint32_t>(alloc->offsets[p]);
        words[2 * p + 1] =
            alloc->capacity[p] | (alloc->kind[p] == StoreKind::MaxHeap ? kAllocHeapBit : 0u);
      }
      const GLuint a = fb.make("allocation", uint64_t{pixels} * 8, words.data());
      if (a) fb.bindTexture(a, GL_RG32UI, kBindAllocation);
    }
  }

  // n(p): the counts given, those on the device, a count pass (the A-buffer needs n(p) before
  // its capture), or counted by the capture itself (countInCapture: no pass of its own)
  void countFragments() {
    const GlRenderOptions& options = plan.options;
    const uint32_t pixels = plan.pixels;
    const bool device = plan.device;
    const bool counted = device || (options.counts && options.counts->size() == pixels);
    counts = fb.make("counts", uint64_t{pixels} * 4,
                     counted && !device ? options.counts->data() : nullptr);
    if (device)  // n(p) of countOnDevice, copied on the GPU
      glCopyNamedBufferSubData(s.deviceCounts, counts, 0, 0, uint64_t{pixels} * 4);
    const bool countPass = countPassFirst(plan.technique);
    countInCapture = !counted && !countPass;
    if (countInCapture) clearUint(counts, 0);
    if (!counted && countPass) {
      clearUint(counts, 0);
      pass("count", [&] {
        glUseProgram(s.program(ProgramId::Count));
        fb.bindImage(counts, kBindCounts);
        s.drawScene();
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT |
                        GL_BUFFER_UPDATE_BARRIER_BIT);
      });
    }
  }

  // dfaoit: the per-pixel sums (dfaoit.frag)
  void captureDfaoit() {
    // T = 1 and the nearest node empty (kFarDepthBits); the rest 0
    static_assert(kDfaoitWords == 13);
    std::array<uint32_t, kDfaoitWords> pixel{};
    pixel[8] = std::bit_cast<uint32_t>(1.0f);
    pixel[11] = kFarDepthBits;
    const GLuint locks = makeAccumulators(pixel);
    pass("capture", [&] {
      const GLuint p = s.program(ProgramId::Dfaoit);
      useCapture(p);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindAccum, accum);
      fb.bindImage(locks, kBindLocks);
      s.drawScene();
      glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    });
  }

  // stochastic, stochastic-strat: the sample depths (kStochasticFarDepth), T = 1, the sums 0;
  // three passes of stochastic.frag
  void captureStochastic() {
    std::array<uint32_t, kStochasticWords> pixel{};
    for (int j = 0; j < kStochasticSamples; ++j)
      pixel[j] = std::bit_cast<uint32_t>(method_math::kStochasticFarDepth);
    pixel[kStochasticSamples] = std::bit_cast<uint32_t>(1.0f);
    const GLuint locks = makeAccumulators(pixel);
    const bool stratified = plan.method.compositing == Compositing::StochasticStrat8;
    const auto draw = [&](GLuint passIndex) {
      const GLuint p = variant(ProgramId::Stochastic, stochasticSwitches(passIndex, stratified));
      // every pass binds the counts image, though only the capture (uPass 2) counts: bound for
      // pass 2 alone, its imageAtomicAdd never reached the buffer on llvmpipe (Mesa 22.3.6; the
      // unit's binding and the uniforms queried right, n(p) read back 0, the sums intact)
      useCapture(p);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindAccum, accum);
      fb.bindImage(locks, kBindLocks);
      s.drawScene();
      glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    };
    pass("total-alpha", [&] { draw(0); });
    pass("stochastic-depth", [&] { draw(1); });
    pass("capture", [&] { draw(2); });
  }

  // hashed-alpha: the z-buffer of the kept fragments (kStochasticFarDepth: none kept)
  void captureHashedAlpha() {
    const std::array<uint32_t, kHashedAlphaWords> pixel{
        std::bit_cast<uint32_t>(method_math::kStochasticFarDepth), 0u};
    const GLuint locks = makeAccumulators(pixel);
    pass("capture", [&] {
      const GLuint p = s.program(ProgramId::HashedAlpha);
      useCapture(p);
      // the CPU engine's SurfacePoints: the fitted camera's inverse view, near and far
      const glm::mat4 inverseView = glm::inverse(viewMatrix(s.camera));
      glProgramUniformMatrix4fv(p, loc(p, "uInverseView"), 1, GL_FALSE, &inverseView[0][0]);
      glProgramUniform2f(p, loc(p, "uNearFar"), s.camera.zNear, s.camera.zFar);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindAccum, accum);
      fb.bindImage(locks, kBindLocks);
      s.drawScene();
      glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    });
  }

  // dfaoit: features, the network and the composite per pixel (dfaoit_resolve.comp)
  Result<void> resolveDfaoit() {
    const std::vector<float>& weights = builtinDfaoitWeights();
    if (weights.size() != kDfaoitWeightCount)
      return makeError("--engine gl: " + plan.method.name + ": " +
                       builtinDfaoitModel().error().message);
    const GLuint net = fb.make("network", weights.size() * 4, weights.data());
    image = fb.make("image", uint64_t{plan.pixels} * 12);
    pass("resolve", [&] {
      const GLuint p = s.program(ProgramId::DfaoitResolve);
      useResolve(p);
      glProgramUniform1f(p, loc(p, "uInv255"), 1.0f / 255.0f);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindAccum, accum);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindDfaoitWeights, net);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindImage, image);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindColorTables, s.colorTables);
      dispatchPixels();
    });
    return {};
  }

  // wboit, mboit, aoit: the per-pixel accumulators (mboit: its moments first; aoit: its nodes)
  void captureAccumulators() {
    const bool isWboit = plan.technique == GlTechnique::Wboit;
    const bool isAoit = plan.technique == GlTechnique::Aoit;
    const uint32_t aoitNodes = static_cast<uint32_t>(aoitNodeCount(plan.method.compositing));
    const uint32_t accumWords = isWboit  ? kWboitWords
                                : isAoit ? aoitWords(plan.method)
                                         : mboitWords(plan.method);
    // wboit: revealage 1; aoit: unused nodes (kAoitEmptyDepth, transmittance 1); the rest 0
    std::vector<uint32_t> pixel(accumWords, 0u);
    if (isWboit) pixel[4] = std::bit_cast<uint32_t>(1.0f);
    if (isAoit)
      for (uint32_t j = 0; j < aoitNodes; ++j) {
        pixel[kAoitNodeWords * j] = std::bit_cast<uint32_t>(kAoitEmptyDepth);
        pixel[kAoitNodeWords * j + 1] = std::bit_cast<uint32_t>(1.0f);
      }
    const GLuint locks = makeAccumulators(pixel);
    // the programs' switches: the AOIT nodes, or the MBOIT moments
    const Compositing c = plan.method.compositing;
    const std::string switches = isWboit ? std::string()
                                 : isAoit
                                     ? aoitSwitches(aoitNodes)
                                     : mboitSwitches(static_cast<uint32_t>(mboitMomentCount(c)),
                                                     mboitTrigonometric(c), mboitQuantized(c));
    auto accumulate = [&](ProgramId id, bool capture) {
      const GLuint program = variant(id, switches);
      if (capture) {
        useCapture(program);
      } else {
        glUseProgram(program);
      }
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindAccum, accum);
      fb.bindImage(locks, kBindLocks);
      s.drawScene();
      glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    };
    if (isAoit)
      pass("visibility", [&] { accumulate(ProgramId::AoitVisibility, false); });
    else if (!isWboit)
      pass("moments", [&] { accumulate(ProgramId::MboitMoments, false); });
    pass("capture", [&] {
      accumulate(isWboit  ? ProgramId::Wboit
                 : isAoit ? ProgramId::AoitColor
                          : ProgramId::MboitColor,
                 true);
    });
  }

  // mlab: k nodes per pixel merged in place, their count per pixel
  void captureMlab() {
    const uint32_t pixels = plan.pixels;
    const uint32_t k = plan.k;
    nodes = fb.make("nodes", uint64_t{pixels} * k * kMlabWords * 4);
    accum = fb.make("counters", uint64_t{pixels} * 4);  // nodes in use per pixel
    clearUint(accum, 0);
    const GLuint locks = fb.make("locks", uint64_t{pixels} * 4);
    clearUint(locks, kLockFree);
    pass("capture", [&] {
      const GLuint p = s.program(ProgramId::Mlab);
      useCapture(p);
      glProgramUniform1ui(p, loc(p, "uK"), k);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindNodes, nodes);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindFill, accum);
      fb.bindImage(locks, kBindLocks);
      s.drawScene();
      glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    });
  }

  // the A-buffer: the prefix sum of n(p), then every fragment into its slot
  Result<void> captureABuffer() {
    const MethodDesc& method = plan.method;
    const uint32_t pixels = plan.pixels;
    offsets = fb.make("offsets", uint64_t{pixels} * 4);
    pass("prefix sum", [&] { s.scan(fb, counts, offsets, pixels); });
    // the total in 64 bits from n(p) itself (the 32-bit scan would wrap silently)
    std::vector<uint32_t> n(pixels);
    glGetNamedBufferSubData(counts, 0, uint64_t{pixels} * 4ll, n.data());
    nodeCount = 0;
    for (uint32_t c : n) nodeCount += c;
    if (nodeCount * kNodeBytes > s.maxBlockBytes)  // (also keeps the uint offsets exact)
      return s.tooLarge(method, "A-buffer node", nodeCount * kNodeBytes);
    nodes = fb.make("nodes", nodeCount * kNodeBytes);
    const GLuint fill = fb.make("fill counters", uint64_t{pixels} * 4);
    clearUint(fill, 0);
    pass("capture", [&] {
      glUseProgram(s.program(ProgramId::ABuffer));
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindOffsets, offsets);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindNodes, nodes);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindFill, fill);
      s.drawScene();
      glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    });
    return {};
  }

  // occupancy culling: depth range, bitmap fill, k-th occupied bucket; the range buffer
  GLuint occupancyCulling(uint32_t words) {
    const uint32_t pixels = plan.pixels;
    const uint32_t k = plan.k;
    const bool perPixel = plan.perPixel;
    const GLuint range = fb.make("occupancy", uint64_t{pixels} * kOccupancyWords * 4);
    static_assert(kOccupancyWords == 3);
    const uint32_t init[3] = {kFarDepthBits, 0u, kOccupancyNoCulling};
    glClearNamedBufferData(range, GL_RGB32UI, GL_RGB_INTEGER, GL_UNSIGNED_INT, init);
    const GLuint bitmap = fb.make("occupancy", uint64_t{pixels} * words * 4);
    clearUint(bitmap, 0);
    pass("depth range", [&] {
      glUseProgram(s.program(ProgramId::DepthRange));
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindOccupancy, range);
      s.drawScene();
      glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    });
    pass("occupancy fill", [&] {
      const GLuint p = s.program(ProgramId::OccupancyFill);
      glUseProgram(p);
      glProgramUniform1ui(p, loc(p, "uWords"), words);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindOccupancy, range);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindOccBits, bitmap);
      s.drawScene();
      glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    });
    pass("occupancy count", [&] {
      const GLuint p = s.program(ProgramId::OccupancyCount);
      glUseProgram(p);
      glProgramUniform1ui(p, loc(p, "uPixels"), pixels);
      glProgramUniform1ui(p, loc(p, "uWords"), words);
      glProgramUniform1ui(p, loc(p, "uK"), k);
      glProgramUniform1ui(p, loc(p, "uPerPixel"), perPixel ? 1u : 0u);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindOccBits, bitmap);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindOccupancy, range);
      dispatchGroups((pixels + kResolveGroupSize - 1) / kResolveGroupSize);
      glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    });
    return range;
  }

  // the k-buffer family: fixed or per-pixel k, max-array or max-heap, optional tail and occupancy
  void captureKBuffer() {
    const MethodDesc& method = plan.method;
    const uint32_t pixels = plan.pixels;
    const uint32_t k = plan.k;
    const bool perPixel = plan.perPixel;
    const bool hybrid = plan.hybrid;
    const uint64_t allocSlots = plan.allocSlots;
    nodeCount = perPixel ? allocSlots : uint64_t{pixels} * k;
    const uint32_t words = static_cast<uint32_t>(method.occupancyWords);
    constexpr uint32_t kStatWords = kCaptureStatSlots * kCaptureStatStride;
    const GLuint stats = fb.make("capture counters", kStatWords * 4);
    clearUint(stats, 0);
    if (hybrid) {
      tails = fb.make("tails", uint64_t{pixels} * kTailWords * 4);
      clearUint(tails, 0);
    } else {
      tails = stats;  // not read
    }
    GLuint range = stats;
    if (words > 0) range = occupancyCulling(words);
    // a fixed k without tail or occupancy takes 64-bit atomicMin where the driver has them
    const bool atomic =
        s.program(ProgramId::KBufferAtomic64) != 0 && !perPixel && !hybrid && words == 0;
    out.atomic64 = atomic;
    nodes = fb.make("nodes", nodeCount * kNodeBytes);
    // the far node: every word kFarDepthBits (a one-word clear, twice as fast as a two-word one
    // on llvmpipe: 8 against 16 ms for 72 MiB); as uint64 words (colour 0, depth) for the atomic
    // capture
    if (atomic) {
      const uint32_t far[2] = {0u, kFarDepthBits};
      glClearNamedBufferData(nodes, GL_RG32UI, GL_RG_INTEGER, GL_UNSIGNED_INT, far);
    } else {
      clearUint(nodes, kFarDepthBits);
    }
    // (the lock words stay allocated and charged with the atomics: bytes_used does not depend
    // on the capture's synchronisation)
    const GLuint locks = fb.make("locks", uint64_t{pixels} * 4);
    clearUint(locks, kLockFree);
    const GLuint p =
        atomic ? s.program(ProgramId::KBufferAtomic64)
               : variant(ProgramId::KBuffer,
                         kbufferSwitches(
                             perPixel,
                             method.store == StoreChoice::MaxHeap ? kStoreMaxHeap : kStoreMaxArray,
                             words > 0, hybrid));
    glProgramUniform1ui(p, loc(p, "uK"), k);
    glProgramUniform1ui(p, loc(p, "uOccupancyWords"), words);
    pass("capture", [&] {
      useCapture(p);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindNodes, nodes);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindOccupancy, range);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindTails, tails);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindCaptureStats, stats);
      fb.bindImage(locks, kBindLocks);
      s.drawScene();
      glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    });
    if (atomic)
      pass("node words", [&] {
        const GLuint q = s.program(ProgramId::SwapNodeWords);
        glUseProgram(q);
        glProgramUniform1ui(q, loc(q, "uCount"), static_cast<GLuint>(nodeCount));
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindNodes, nodes);
        dispatchGroups((nodeCount + kResolveGroupSize - 1) / kResolveGroupSize);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
      });
    std::vector<uint32_t> culled(kStatWords);
    glGetNamedBufferSubData(stats, 0, kStatWords * 4, culled.data());
    out.culledOccupancy = out.culledKPlus = 0;
    for (uint32_t slot = 0; slot < kStatWords; slot += kCaptureStatStride) {
      out.culledOccupancy += culled[slot];
      out.culledKPlus += culled[slot + 1];
    }
  }

  // linked lists: the heads, the pool and its counter [, the tails]; a node per fragment while
  // the pool lasts (capture_list.frag)
  void captureList() {
    const uint32_t pixels = plan.pixels;
    nodeCount = plan.allocSlots;
    heads = fb.make("heads", uint64_t{pixels} * 4);
    clearUint(heads, kListEnd);
    nodes = fb.make("nodes", std::max<uint64_t>(nodeCount, 1) * kListNodeWords * 4);
    const GLuint counter = fb.make("pool counter", 4);
    clearUint(counter, 0);
    if (plan.hybrid) {
      tails = fb.make("tails", uint64_t{pixels} * kTailWords * 4);
      clearUint(tails, 0);
    }
    pass("capture", [&] {
      const GLuint p = variant(ProgramId::ListCapture, listSwitches(plan.hybrid));
      useCapture(p);
      glProgramUniform1ui(p, loc(p, "uPoolSize"), static_cast<GLuint>(nodeCount));
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindListHeads, heads);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindNodes, nodes);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindFill, counter);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindTails, tails ? tails : counter);
      s.drawScene();
      glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    });
  }

  // linked lists: each list walked, sorted in place and composited (resolve_list.comp); the
  // lengths (k(p)) in `offsets`
  void resolveList() {
    const uint32_t pixels = plan.pixels;
    image = fb.make("image", uint64_t{pixels} * 12);
    offsets = fb.make("lengths", uint64_t{pixels} * 4);
    pass("resolve", [&] {
      const GLuint p = variant(ProgramId::ListResolve, listSwitches(plan.hybrid));
      useResolve(p);
      glProgramUniform1f(p, loc(p, "uInv255"), 1.0f / 255.0f);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindListHeads, heads);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindListLengths, offsets);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindNodes, nodes);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindImage, image);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindResolveTails, tails ? tails : offsets);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindColorTables, s.colorTables);
      dispatchPixels();
    });
  }

  // linked lists: each pixel's sorted list as nodes, offsets and counts
  void readLists() {
    const uint32_t pixels = plan.pixels;
    std::vector<uint32_t> head(pixels), pool(nodeCount * kListNodeWords);
    glGetNamedBufferSubData(heads, 0, uint64_t{pixels} * 4ll, head.data());
    if (nodeCount > 0)
      glGetNamedBufferSubData(nodes, 0, static_cast<GLsizeiptr>(pool.size() * 4), pool.data());
    out.nodes.clear();
    out.nodeOffsets.resize(pixels);
    out.nodeCounts.resize(pixels);
    for (uint32_t p = 0; p < pixels; ++p) {
      out.nodeOffsets[p] = out.nodes.size();
      for (uint32_t i = head[p]; i != kListEnd && i < nodeCount; i = pool[kListNodeWords * i + 2])
        out.nodes.push_back((static_cast<uint64_t>(pool[kListNodeWords * i]) << 32) |
                            pool[kListNodeWords * i + 1]);
      out.nodeCounts[p] = static_cast<uint32_t>(out.nodes.size() - out.nodeOffsets[p]);
    }
  }

  // depth peeling (peel.frag, peel_step.comp): passes until one peels every fragment still in
  // range (the frame's two counters read back after each) or --max-peels, then under hybrid the
  // tail pass when fragments remain
  void capturePeel() {
    const MethodDesc& method = plan.method;
    const uint32_t pixels = plan.pixels;
    const bool dual = method.compositing == Compositing::DualPeel;
    const uint32_t words = peelWords(method);
    accum = fb.make("accumulators", uint64_t{pixels} * words * 4);
    {  // mfr::PeelPixel / mfr::DualPeelPixel's initial words
      std::vector<uint32_t> init(uint64_t{pixels} * words, 0u);
      const uint32_t one = std::bit_cast<uint32_t>(1.0f), none = 0xffffffffu;
      for (uint64_t w = 0; w < init.size(); w += words) {
        if (dual) {
          init[w + 2] = init[w + 3] = init[w + 4] = init[w + 5] = none;  // hi, nearest
          init[w + 13] = init[w + 17] = one;                             // front T, back T
        } else {
          init[w + 2] = init[w + 3] = none;  // candidate
          init[w + 8] = one;                 // T
        }
      }
      glNamedBufferSubData(accum, 0, static_cast<GLsizeiptr>(init.size() * 4), init.data());
    }
    const GLuint locks = fb.make("locks", uint64_t{pixels} * 4);
    clearUint(locks, kLockFree);
    peeled = fb.make("peeled", uint64_t{pixels} * 4);  // fragments peeled per pixel (statistics)
    clearUint(peeled, 0);
    const GLuint stats = fb.make("capture counters", 8);
    if (plan.hybrid) {
      tails = fb.make("tails", uint64_t{pixels} * kTailWords * 4);
      clearUint(tails, 0);
    }
    const GLuint step = variant(ProgramId::PeelStep, peelStepSwitches(dual));
    glProgramUniform1ui(step, loc(step, "uPixels"), pixels);
    glProgramUniform1f(step, loc(step, "uInv255"), 1.0f / 255.0f);
    const auto geometry = [&](bool tail) {
      useCapture(variant(ProgramId::Peel, peelSwitches(dual, tail)));
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindAccum, accum);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindCaptureStats, stats);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindTails, tails ? tails : stats);
      fb.bindImage(locks, kBindLocks);
      s.drawScene();
      glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    };
    const std::optional<uint32_t> maxPeels = method.maxPeels;
    uint32_t passes = 0;
    bool remaining = true;
    while (remaining && (!maxPeels || passes < *maxPeels) && !fb.failure) {
      clearUint(stats, 0);
      const std::string name = peelPassName(passes);
      pass(name.c_str(), [&] {
        geometry(false);
        glUseProgram(step);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindAccum, accum);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindCaptureStats, stats);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindOffsets, peeled);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindColorTables, s.colorTables);
        dispatchPixels();
      });
      countInCapture = false;         // n(p) once, in the first pass
      uint32_t counters[2] = {0, 0};  // fragments in range, fragments peeled
      glGetNamedBufferSubData(stats, 0, 8, counters);
      ++passes;
      remaining = counters[1] < counters[0];
    }
    out.peelPasses = passes;
    if (remaining && plan.hybrid) pass(kPeelTailPass, [&] { geometry(true); });
  }

  // depth peeling: the front layers over [the tail over] [the back layers over] the background
  void resolvePeel() {
    image = fb.make("image", uint64_t{plan.pixels} * 12);
    pass("resolve", [&] {
      const GLuint p = variant(
          ProgramId::PeelResolve,
          peelResolveSwitches(plan.method.compositing == Compositing::DualPeel, plan.hybrid));
      useResolve(p);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindAccum, accum);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindResolveTails, tails ? tails : accum);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindImage, image);
      dispatchPixels();
    });
  }

  // mlab: its nodes front to back over the background
  void resolveMlab() {
    image = fb.make("image", uint64_t{plan.pixels} * 12);
    pass("resolve", [&] {
      const GLuint p = s.program(ProgramId::MlabResolve);
      useResolve(p);
      glProgramUniform1ui(p, loc(p, "uK"), plan.k);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindNodes, nodes);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindFill, accum);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindImage2, image);
      dispatchPixels();
    });
  }

  // wboit, mboit, aoit: the accumulators' composite
  void resolveAccumulators(ProgramId program) {
    image = fb.make("image", uint64_t{plan.pixels} * 12);
    pass("resolve", [&] {
      const GLuint p =
          program == ProgramId::AoitResolve
              ? variant(program,
                        aoitSwitches(static_cast<uint32_t>(aoitNodeCount(plan.method.compositing))))
              : s.program(program);
      useResolve(p);
      if (program == ProgramId::MboitResolve)
        glProgramUniform1ui(p, loc(p, "uMomentWords"), mboitMomentWords(plan.method));
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindAccum, accum);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindImage, image);
      if (program == ProgramId::HashedAlphaResolve)
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindColorTables, s.colorTables);
      dispatchPixels();
    });
  }

  // the A-buffer and the k-buffer family: sort each pixel's nodes, composite front to back
  // (kbuffer or hybrid with the pixel's tail)
  void resolveNodes() {
    image = fb.make("image", uint64_t{plan.pixels} * 12);
    const bool fixedK = !plan.perPixel && plan.technique == GlTechnique::KBuffer;
    const uint32_t layout = plan.perPixel ? kResolvePerPixel
                            : fixedK      ? kResolveFixedK
                                          : kResolveABuffer;
    const GLuint p =
        variant(ProgramId::Resolve,
                resolveSwitches(layout, plan.hybrid, fixedK && plan.k <= kResolveLocalNodes,
                                plan.options.readNodes));
    pass("resolve", [&] {
      useResolve(p);
      glProgramUniform1ui(p, loc(p, "uK"), plan.k);
      glProgramUniform1f(p, loc(p, "uInv255"), 1.0f / 255.0f);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindResolveTails, tails ? tails : counts);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindCounts, counts);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindOffsets, offsets ? offsets : counts);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindNodes, nodes);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindImage, image);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindColorTables, s.colorTables);
      dispatchPixels();
    });
  }

  // a resolve program in use with the uniforms every resolve takes
  void useResolve(GLuint p) {
    const glm::vec3 bg = plan.options.background;
    glUseProgram(p);
    glProgramUniform1ui(p, loc(p, "uPixels"), plan.pixels);
    glProgramUniform3f(p, loc(p, "uBackground"), bg.r, bg.g, bg.b);
  }

  // one invocation per pixel, then the image readable
  void dispatchPixels() {
    dispatchGroups((plan.pixels + kResolveGroupSize - 1) / kResolveGroupSize);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
  }

  // a GL error or a buffer GL could not allocate
  Result<void> checkErrors() {
    const MethodDesc& method = plan.method;
    if (const GLenum e = glGetError(); e != GL_NO_ERROR) {
      if (fb.failure) return *fb.failure;
      return makeError("--engine gl: " + method.name + " failed (GL error " + glErrorText(e) + ")");
    }
    if (fb.failure) return *fb.failure;
    return {};
  }

  // n(p), the image and, with readNodes, the nodes with their per-pixel ranges
  void readBack() {
    const GlRenderOptions& options = plan.options;
    const uint32_t pixels = plan.pixels;
    out.counts.resize(pixels);
    glGetNamedBufferSubData(counts, 0, uint64_t{pixels} * 4ll, out.counts.data());
    for (uint32_t n : out.counts) out.fragments += n;
    out.image = ImageRGB(s.width, s.height);
    glGetNamedBufferSubData(image, 0, uint64_t{pixels} * 12ll, out.image.pixels.data());
    if (options.readNodes && fragmentNodes(plan.technique)) readNodes();
    if (peeled) {  // depth peeling: the fragments it peeled, per pixel
      out.held.resize(pixels);
      glGetNamedBufferSubData(peeled, 0, uint64_t{pixels} * 4ll, out.held.data());
    }
    if (plan.technique == GlTechnique::LinkedList) {
      out.held.resize(pixels);
      glGetNamedBufferSubData(offsets, 0, uint64_t{pixels} * 4ll, out.held.data());
      if (options.readNodes) readLists();
    }
  }

  // the nodes, and each pixel's first node and count
  void readNodes() {
    const Allocation* alloc = plan.alloc;
    const uint32_t pixels = plan.pixels;
    const uint32_t k = plan.k;
    const bool device = plan.device;
    const bool isABuffer = plan.technique == GlTechnique::ABuffer;
    std::vector<uint32_t> words(nodeCount * 2);
    if (nodeCount > 0)
      glGetNamedBufferSubData(nodes, 0, static_cast<GLsizeiptr>(nodeCount * kNodeBytes),
                              words.data());
    out.nodes.resize(nodeCount);
    for (uint64_t i = 0; i < nodeCount; ++i)
      out.nodes[i] = (static_cast<uint64_t>(words[2 * i + kNodeHiIndex]) << 32) |
                     words[2 * i + 1 - kNodeHiIndex];
    out.nodeOffsets.resize(pixels);
    out.nodeCounts.resize(pixels);
    if (isABuffer) {
      std::vector<uint32_t> off(pixels);
      glGetNamedBufferSubData(offsets, 0, uint64_t{pixels} * 4ll, off.data());
      for (uint32_t p = 0; p < pixels; ++p) {
        out.nodeOffsets[p] = off[p];
        out.nodeCounts[p] = out.counts[p];
      }
    } else {
      std::vector<uint32_t> words;
      if (device) {
        words.resize(uint64_t{pixels} * 2);
        glGetNamedBufferSubData(s.deviceWords, 0, uint64_t{pixels} * 8ll, words.data());
      }
      for (uint32_t p = 0; p < pixels; ++p) {
        const uint64_t first = device ? words[2 * p] : alloc ? alloc->offsets[p] : uint64_t{p} * k;
        const uint32_t capacity = device  ? words[2 * p + 1] & ~kAllocHeapBit
                                  : alloc ? alloc->capacity[p]
                                          : k;
        out.nodeOffsets[p] = first;
        out.nodeCounts[p] = std::min(out.counts[p], capacity);
      }
    }
  }
};

Result<RenderPlan> GlEngine::State::planRender(const MethodDesc& method,
                                               const GlRenderOptions& options) const {
  auto technique = classifyGl(method);
  if (!technique) return technique.error();
  const Allocation* alloc = options.allocation;
  // the allocation the compute shaders left in the engine's buffers (allocateCapped,
  // allocateByImportance), else the host's
  const bool device = options.deviceAllocation;
  if (device && !this->device)
    return makeError("--engine gl: " + method.name + ": no allocation on the device");
  if (alloc && (alloc->capacity.size() != pixels() || alloc->offsets.size() != pixels() ||
                alloc->kind.size() != pixels()))
    return makeError("--engine gl: " + method.name + ": an allocation of another size");
  RenderPlan plan{method, options, *technique, alloc, pixels(), device, false, 0, false, 0};
  switch (*technique) {
    case GlTechnique::ABuffer:
    case GlTechnique::Wboit:
    case GlTechnique::Mboit:
    case GlTechnique::Aoit:
    case GlTechnique::Dfaoit:
    case GlTechnique::Stochastic:
    case GlTechnique::HashedAlpha:
      break;
    case GlTechnique::LinkedList:
      plan.allocSlots = options.poolNodes;
      plan.hybrid = method.compositing == Compositing::Hybrid;
      if (plan.allocSlots * kListNodeWords * 4 > maxBlockBytes)
        return tooLarge(method, "node pool", plan.allocSlots * kListNodeWords * 4);
      break;
    case GlTechnique::Peel:
      plan.hybrid = method.peelTail;
      break;
    case GlTechnique::KBuffer:
      plan.perPixel = alloc != nullptr || device;
      plan.allocSlots = device ? deviceSlots : alloc ? alloc->slots : 0;
      plan.hybrid = method.compositing == Compositing::Hybrid;
      if (plan.perPixel) break;
      [[fallthrough]];  // a fixed k
    case GlTechnique::Mlab:
      if (method.allocation != AllocationPolicy::FixedK || !method.k || *method.k == 0)
        return makeError("--engine gl: " + method.name +
                         ": a fixed k (k >= 1) or a per-pixel allocation needed");
      plan.k = *method.k;
      break;
  }
  const uint64_t perPixelBytes = uint64_t{plan.pixels} * largestPerPixelBytes(plan);
  if (perPixelBytes > maxBlockBytes) return tooLarge(method, "per-pixel", perPixelBytes);
  if (plan.perPixel && plan.allocSlots * kNodeBytes > maxBlockBytes)  // (keeps uint offsets exact)
    return tooLarge(method, "node", plan.allocSlots * kNodeBytes);
  return plan;
}

Error GlEngine::State::tooLarge(const MethodDesc& method, const std::string& what,
                                uint64_t bytes) const {
  return makeError("--engine gl: " + method.name + " at " + std::to_string(width) + "x" +
                   std::to_string(height) + ": the " + what + " buffer needs " +
                   std::to_string(bytes) + " B, above GL_MAX_SHADER_STORAGE_BLOCK_SIZE (" +
                   std::to_string(maxBlockBytes) + " B)");
}

Result<GlRenderOutput> GlEngine::render(const MethodDesc& method, const GlRenderOptions& options) {
  State& s = *state_;
  auto plan = s.planRender(method, options);
  if (!plan) return plan.error();
  GlRenderOutput out;
  for (int run = options.warmUp ? 0 : 1; run < 2; ++run) {
    const bool timed = run == 1;
    out.bufferBytes = s.sceneBytes;
    out.passes.clear();
    State::FrameRun frame(s, *plan, out);
    frame.bindAllocation();
    frame.countFragments();
    switch (plan->technique) {
      case GlTechnique::ABuffer:
        MFR_TRY(frame.captureABuffer());
        frame.resolveNodes();
        break;
      case GlTechnique::KBuffer:
        frame.captureKBuffer();
        frame.resolveNodes();
        break;
      case GlTechnique::Wboit:
        frame.captureAccumulators();
        frame.resolveAccumulators(ProgramId::WboitResolve);
        break;
      case GlTechnique::Mboit:
        frame.captureAccumulators();
        frame.resolveAccumulators(ProgramId::MboitResolve);
        break;
      case GlTechnique::Mlab:
        frame.captureMlab();
        frame.resolveMlab();
        break;
      case GlTechnique::Aoit:
        frame.captureAccumulators();
        frame.resolveAccumulators(ProgramId::AoitResolve);
        break;
      case GlTechnique::LinkedList:
        frame.captureList();
        frame.resolveList();
        break;
      case GlTechnique::Peel:
        frame.capturePeel();
        frame.resolvePeel();
        break;
      case GlTechnique::Dfaoit:
        frame.captureDfaoit();
        MFR_TRY(frame.resolveDfaoit());
        break;
      case GlTechnique::Stochastic:
        frame.captureStochastic();
        frame.resolveAccumulators(ProgramId::StochasticResolve);
        break;
      case GlTechnique::HashedAlpha:
        frame.captureHashedAlpha();
        frame.resolveAccumulators(ProgramId::HashedAlphaResolve);
        break;
    }
    MFR_TRY(frame.checkErrors());
    if (timed) frame.readBack();
  }
  return out;
}

}  // namespace mfr::gl
