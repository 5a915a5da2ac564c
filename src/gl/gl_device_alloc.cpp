// The variable-k allocation in compute shaders (GlEngine::countOnDevice, allocateCapped,
// allocateByImportance and their read-backs), the prefix sum, and the deep k-buffer's feature and
// inference passes (dkbImportance): the allocation stays in the engine's buffers for render().
#include <epoxy/gl.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <vector>

#include "gl/gl_state.hpp"
#include "mfr/gl/gl_engine.hpp"
#include "mfr/gl/shared_layout.h"
#include "mfr/method/method_math.h"

namespace mfr::gl {

// exclusive prefix sum of `count` uints of `in` into `out`
void GlEngine::State::scan(FrameBuffers& fb, GLuint in, GLuint out, uint32_t count) const {
  constexpr uint32_t perBlock = kScanGroupSize * kScanItemsPerThread;
  const uint32_t blocks = (count + perBlock - 1) / perBlock;
  const GLuint sums = fb.make("prefix sum block sums", uint64_t{blocks} * 4);
  const GLuint scanProgram = program(ProgramId::PrefixSum);
  glUseProgram(scanProgram);
  glProgramUniform1ui(scanProgram, loc(scanProgram, "uCount"), count);
  glProgramUniform1ui(scanProgram, loc(scanProgram, "uBlocks"), blocks);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindScanIn, in);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindScanOut, out);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindScanSums, sums);
  dispatchGroups(blocks);
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
  if (blocks <= 1) return;
  const GLuint scanned = fb.make("prefix sum block sums", uint64_t{blocks} * 4);
  scan(fb, sums, scanned, blocks);
  const GLuint addProgram = program(ProgramId::PrefixSumAdd);
  glUseProgram(addProgram);
  glProgramUniform1ui(addProgram, loc(addProgram, "uCount"), count);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindScanOut, out);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindScanSums, scanned);
  dispatchGroups((count + kScanGroupSize - 1) / kScanGroupSize);
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
}

// k(p) by alloc_k.comp (the uniforms set by the caller; `totals` cleared), then the prefix sum
// and the packed per-pixel words; the totals read back
Result<GlAllocationTotals> GlEngine::State::allocateK(FrameBuffers& fb, GLuint totals,
                                                      GLuint importance, GLuint total,
                                                      StoreChoice store,
                                                      std::vector<GlPassTime>* passes) {
  const uint32_t pixels = this->pixels();
  const uint64_t groups = (uint64_t{pixels} + kResolveGroupSize - 1) / kResolveGroupSize;
  deviceCapacity = device->make("k(p)", uint64_t{pixels} * 4);
  deviceReserved = device->make("k(p) allocated", uint64_t{pixels} * 4);
  if (device->failure) return *device->failure;
  if (fb.failure) return *fb.failure;
  timedPass(passes, "k(p)", [&] {
    const GLuint p = program(ProgramId::AllocK);
    glUseProgram(p);
    glProgramUniform1ui(p, loc(p, "uPixels"), pixels);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindAllocCounts, deviceCounts);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindAllocSummary, totals);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindAllocK, deviceCapacity);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindAllocReserved, deviceReserved);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindImportance, importance);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindImportanceTotal, total);
    dispatchGroups(groups);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
  });
  uint32_t words[kAllocTotalWords] = {};
  glGetNamedBufferSubData(totals, 0, sizeof words, words);
  deviceSlots = (uint64_t{words[1]} << 32) | words[0];
  deviceReservedSlots = (uint64_t{words[3]} << 32) | words[2];
  const GLuint offsets = fb.make("allocation offsets", uint64_t{pixels} * 4);
  timedPass(passes, "prefix sum", [&] { scan(fb, deviceCapacity, offsets, pixels); });
  uint32_t storeMode = 0;
  switch (store) {
    case StoreChoice::MaxHeap:
      storeMode = 1;
      break;
    case StoreChoice::PerPixel:
      storeMode = 2;
      break;
    case StoreChoice::Append:
    case StoreChoice::MaxArray:
    case StoreChoice::MultiLayer:
    case StoreChoice::None:
    case StoreChoice::LinkedList:
      storeMode = 0;
      break;
  }
  deviceWords = device->make("allocation", uint64_t{pixels} * 8);
  if (device->failure) return *device->failure;
  if (fb.failure) return *fb.failure;
  timedPass(passes, "allocation words", [&] {
    const GLuint p = program(ProgramId::AllocPack);
    glUseProgram(p);
    glProgramUniform1ui(p, loc(p, "uPixels"), pixels);
    glProgramUniform1ui(p, loc(p, "uStore"), storeMode);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindAllocCounts, deviceCounts);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindAllocK, deviceCapacity);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindAllocOffsets, offsets);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindAllocWords, deviceWords);
    dispatchGroups(groups);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT |
                    GL_BUFFER_UPDATE_BARRIER_BIT);
  });
  if (const GLenum e = glGetError(); e != GL_NO_ERROR)
    return makeError("--engine gl: the variable-k allocation failed (GL error " + glErrorText(e) +
                     ")");
  return GlAllocationTotals{deviceSlots, deviceReservedSlots};
}

Result<std::vector<float>> GlEngine::dkbImportance(const std::vector<float>& weights,
                                                   uint64_t slots,
                                                   std::vector<GlPassTime>* passes) {
  constexpr size_t kWeights = 128 * 12 + 128 + 64 * 128 + 64 + 64 + 1;
  if (weights.size() != kWeights)
    return makeError("--engine gl: the deep k-buffer's network must be 12-128-64-1 on GL");
  State& s = *state_;
  const uint64_t pixels = s.pixels();
  std::map<std::string, uint64_t> ledger;
  FrameBuffers fb(&ledger);
  const GLuint acc = fb.make("features", pixels * kDkbAccWords * 4);
  const GLuint locks = fb.make("locks", pixels * 4);
  const GLuint net = fb.make("network", weights.size() * 4, weights.data());
  const GLuint importance = fb.make("importance", pixels * 4);
  if (fb.failure) return *fb.failure;
  std::vector<uint32_t> words(pixels * kDkbAccWords);
  timedPass(passes, "features", [&] {
    static_assert(kDkbAccWords == 7);
    std::vector<uint32_t> init(pixels * kDkbAccWords, 0u);
    for (uint64_t p = 0; p < pixels; ++p) init[p * kDkbAccWords + 1] = kFarDepthBits;
    glNamedBufferSubData(acc, 0, static_cast<GLsizeiptr>(init.size() * 4), init.data());
    clearUint(locks, kLockFree);
    glUseProgram(s.program(ProgramId::DkbFeatures));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindDkbAcc, acc);
    fb.bindImage(locks, kBindLocks);
    s.drawScene();
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT);
    glGetNamedBufferSubData(acc, 0, static_cast<GLsizeiptr>(words.size() * 4), words.data());
  });
  std::vector<float> out(pixels, 0.0f);
  timedPass(passes, "inference", [&] {
    // the image's statistics (mfr::ImageFeatureStats) on the host: four numbers
    uint64_t fragments = 0, covered = 0;
    float nearest = 1.0f, farthest = 0.0f;
    for (uint64_t p = 0; p < pixels; ++p) {
      const uint32_t* a = &words[p * kDkbAccWords];
      if (a[0] == 0) continue;
      fragments += a[0];
      ++covered;
      nearest = std::min(nearest, std::bit_cast<float>(a[1]));
      farthest = std::max(farthest, std::bit_cast<float>(a[3]));
    }
    if (fragments == 0) return;
    const GLuint p = s.program(ProgramId::DkbInfer);
    glUseProgram(p);
    glProgramUniform1ui(p, loc(p, "uPixels"), static_cast<GLuint>(pixels));
    glProgramUniform1d(p, loc(p, "uMeanN"), static_cast<double>(fragments) / covered);
    glProgramUniform1f(p, loc(p, "uNearest"), nearest);
    glProgramUniform1f(p, loc(p, "uFarthest"), farthest);
    glProgramUniform1f(p, loc(p, "uSlotShare"),
                       static_cast<float>(std::min(1.0, static_cast<double>(slots) / fragments)));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindDkbAcc, acc);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindDkbWeights, net);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindDkbImportance, importance);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindColorTables, s.colorTables);
    dispatchGroups((pixels + kResolveGroupSize - 1) / kResolveGroupSize);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    glGetNamedBufferSubData(importance, 0, static_cast<GLsizeiptr>(pixels * 4), out.data());
  });
  if (const GLenum e = glGetError(); e != GL_NO_ERROR)
    return makeError("--engine gl: the deep k-buffer's importance failed (GL error " +
                     glErrorText(e) + ")");
  return out;
}

Result<CountSummary> GlEngine::countOnDevice(std::vector<GlPassTime>* passes) {
  State& s = *state_;
  const uint32_t pixels = s.pixels();
  s.deviceLedger.clear();
  s.device = std::make_unique<FrameBuffers>(&s.deviceLedger);
  s.deviceCapacity = s.deviceReserved = s.deviceWords = s.deviceImportance = s.deviceNearest = 0;
  s.deviceSlots = s.deviceReservedSlots = 0;
  s.deviceByImportance = false;
  s.deviceCounts = s.device->make("counts", uint64_t{pixels} * 4);
  if (s.device->failure) return *s.device->failure;
  clearUint(s.deviceCounts, 0);
  timedPass(passes, "count", [&] {
    glUseProgram(s.program(ProgramId::Count));
    s.device->bindImage(s.deviceCounts, kBindCounts);
    s.drawScene();
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
  });
  std::map<std::string, uint64_t> ledger;
  FrameBuffers fb(&ledger);
  const GLuint summary = fb.make("histogram", kAllocSummaryWords * 4);
  if (fb.failure) return *fb.failure;
  clearUint(summary, 0);
  std::vector<uint32_t> words(kAllocSummaryWords);
  timedPass(passes, "histogram", [&] {
    const GLuint p = s.program(ProgramId::AllocHistogram);
    glUseProgram(p);
    glProgramUniform1ui(p, loc(p, "uPixels"), pixels);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindAllocCounts, s.deviceCounts);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindAllocSummary, summary);
    dispatchGroups((uint64_t{pixels} + kResolveGroupSize - 1) / kResolveGroupSize);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    glGetNamedBufferSubData(summary, 0, kAllocSummaryWords * 4, words.data());
  });
  if (const GLenum e = glGetError(); e != GL_NO_ERROR)
    return makeError("--engine gl: the count pass failed (GL error " + glErrorText(e) + ")");
  CountSummary out;
  out.histogram.assign(words.begin(), words.begin() + kAllocHistogramBins);
  out.maxN = words[kAllocHistogramBins];
  out.covered = pixels - out.histogram[0];
  return out;
}

Result<GlAllocationTotals> GlEngine::allocateCapped(uint32_t k, StoreChoice store,
                                                    std::vector<GlPassTime>* passes) {
  State& s = *state_;
  if (!s.device) return makeError("--engine gl: allocateCapped before countOnDevice");
  std::map<std::string, uint64_t> ledger;
  FrameBuffers fb(&ledger);
  const GLuint totals = fb.make("allocation totals", kAllocTotalWords * 4);
  clearUint(totals, 0);
  const GLuint allocK = s.program(ProgramId::AllocK);
  glProgramUniform1ui(allocK, loc(allocK, "uMode"), kAllocCapped);
  glProgramUniform1ui(allocK, loc(allocK, "uK"), k);
  s.deviceByImportance = false;
  return s.allocateK(fb, totals, totals, totals, store, passes);  // (no importance: unread)
}

Result<GlAllocationTotals> GlEngine::allocateByImportance(const ImportanceParams& params,
                                                          const std::vector<float>& previousCosine,
                                                          uint64_t slots, StoreChoice store,
                                                          std::vector<GlPassTime>* passes) {
  State& s = *state_;
  if (!s.device) return makeError("--engine gl: allocateByImportance before countOnDevice");
  const uint32_t pixels = s.pixels();
  const uint64_t groups = (uint64_t{pixels} + kResolveGroupSize - 1) / kResolveGroupSize;
  std::map<std::string, uint64_t> ledger;
  FrameBuffers fb(&ledger);
  // this frame's nearest |n.v| (the output's, and the Fresnel term's unless a previous frame's
  // is given)
  static_assert(kNearestWords == 3);
  s.deviceNearest = s.device->make("nearest", uint64_t{pixels} * kNearestWords * 4);
  if (s.device->failure) return *s.device->failure;
  MFR_TRY(s.nearestPass(fb, s.deviceNearest, passes));
  const bool previous = previousCosine.size() == pixels;
  const GLuint cosine = previous
                            ? fb.make("previous |n.v|", uint64_t{pixels} * 4, previousCosine.data())
                            : s.deviceNearest;
  s.deviceImportance = s.device->make("importance", uint64_t{pixels} * kImportanceWords * 4);
  const GLuint p = s.program(ProgramId::Importance);
  const float width = static_cast<float>(s.width), height = static_cast<float>(s.height);
  // the host's constants of mfr::computeImportance, rounded as there
  const glm::vec2 fovea = params.fovea.value_or(glm::vec2(s.width * 0.5f, s.height * 0.5f));
  const float diagonal = method_math::importanceDiagonal(width, height);
  const float d = params.peripheryExponent;
  const int dInt = d >= 0.0f && d <= 64.0f && std::floor(d) == d ? static_cast<int>(d) : -1;
  namespace mm = method_math;
  const uint64_t seedMix = params.seed * mm::words64(mm::kSplitMixGammaLo, mm::kSplitMixGammaHi) +
                           mm::words64(mm::kSplitMixOffsetLo, mm::kSplitMixOffsetHi);
  glProgramUniform1ui(p, loc(p, "uPixels"), pixels);
  glProgramUniform1ui(p, loc(p, "uWidth"), static_cast<GLuint>(s.width));
  glProgramUniform1f(p, loc(p, "uAlpha"), params.alpha);
  glProgramUniform1f(p, loc(p, "uOneMinusAlpha"), 1.0f - params.alpha);
  glProgramUniform1f(p, loc(p, "uNLimit"), params.nLimit);
  glProgramUniform2f(p, loc(p, "uFovea"), fovea.x, fovea.y);
  glProgramUniform1f(p, loc(p, "uDiagonal"), diagonal);
  glProgramUniform1f(p, loc(p, "uExponent"), d);
  glProgramUniform1i(p, loc(p, "uExponentInt"), dInt);
  glProgramUniform1f(p, loc(p, "uNoise"), params.noise);
  glProgramUniform2ui(p, loc(p, "uSeedMix"), static_cast<GLuint>(seedMix),
                      static_cast<GLuint>(seedMix >> 32));
  glProgramUniform1ui(p, loc(p, "uUse"),
                      (params.useDepth ? 1u : 0u) | (params.usePeriphery ? 2u : 0u) |
                          (params.useFresnel ? 4u : 0u) | (params.useNoise ? 8u : 0u));
  glProgramUniform1ui(p, loc(p, "uCosine"), previous ? kCosineFloats : kCosineNearest);
  timedPass(passes, "importance", [&] {
    glUseProgram(p);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindAllocCounts, s.deviceCounts);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindImportance, s.deviceImportance);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindCosine, cosine);
    dispatchGroups(groups);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
  });
  const GLuint total = fb.make("importance total", 8);
  if (s.device->failure) return *s.device->failure;
  if (fb.failure) return *fb.failure;
  timedPass(passes, "importance total", [&] {
    const GLuint q = s.program(ProgramId::ImportanceTotal);
    glUseProgram(q);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindImportance, s.deviceImportance);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindImportanceTotal, total);
    // in order, kTotalChunk pixels per dispatch (the running sum stays in `total`)
    for (uint32_t first = 0; first < pixels; first += std::min(kTotalChunk, pixels - first)) {
      glProgramUniform1ui(q, loc(q, "uFirst"), first);
      glProgramUniform1ui(q, loc(q, "uEnd"), first + std::min(kTotalChunk, pixels - first));
      glDispatchCompute(1, 1, 1);
      glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    }
  });
  const GLuint totals = fb.make("allocation totals", kAllocTotalWords * 4);
  clearUint(totals, 0);
  const GLuint allocK = s.program(ProgramId::AllocK);
  glProgramUniform1ui(allocK, loc(allocK, "uMode"), kAllocByImportance);
  glProgramUniform1d(allocK, loc(allocK, "uSlots"), static_cast<double>(slots));
  s.deviceByImportance = true;
  return s.allocateK(fb, totals, s.deviceImportance, total, store, passes);
}

Result<Allocation> GlEngine::readDeviceAllocation() {
  State& s = *state_;
  if (!s.device || !s.deviceWords) return makeError("--engine gl: no allocation on the device");
  const uint64_t pixels = s.pixels();
  std::vector<uint32_t> words(pixels * 2);
  glGetNamedBufferSubData(s.deviceWords, 0, static_cast<GLsizeiptr>(pixels * 8), words.data());
  Allocation a;
  a.capacity.resize(pixels);
  a.offsets.resize(pixels);
  a.kind.resize(pixels);
  for (uint64_t p = 0; p < pixels; ++p) {
    a.offsets[p] = words[2 * p];
    a.capacity[p] = words[2 * p + 1] & ~kAllocHeapBit;
    a.kind[p] = (words[2 * p + 1] & kAllocHeapBit) ? StoreKind::MaxHeap : StoreKind::MaxArray;
  }
  a.slots = s.deviceSlots;
  a.reservedSlots = s.deviceByImportance ? s.deviceReservedSlots : s.deviceSlots;
  if (s.deviceByImportance) {
    a.reservedK.resize(pixels);
    glGetNamedBufferSubData(s.deviceReserved, 0, static_cast<GLsizeiptr>(pixels * 4),
                            a.reservedK.data());
  }
  return a;
}

Result<ImportanceMaps> GlEngine::readImportance() {
  State& s = *state_;
  if (!s.device || !s.deviceImportance)
    return makeError("--engine gl: no importance map on the device");
  const uint64_t pixels = s.pixels();
  std::vector<float> words(pixels * kImportanceWords);
  glGetNamedBufferSubData(s.deviceImportance, 0, static_cast<GLsizeiptr>(words.size() * 4),
                          words.data());
  ImportanceMaps m;
  for (std::vector<float>* v : {&m.importance, &m.depth, &m.periphery, &m.fresnel, &m.noise})
    v->resize(pixels);
  for (uint64_t p = 0; p < pixels; ++p) {
    const float* w = &words[p * kImportanceWords];
    m.importance[p] = w[0];
    m.depth[p] = w[1];
    m.periphery[p] = w[2];
    m.fresnel[p] = w[3];
    m.noise[p] = w[4];
  }
  return m;
}

Result<std::vector<float>> GlEngine::readNearestCosine() {
  State& s = *state_;
  if (!s.device || !s.deviceNearest) return makeError("--engine gl: no nearest pass on the device");
  return s.readCosine(s.deviceNearest);
}

Result<void> GlEngine::State::nearestPass(FrameBuffers& fb, GLuint nearest,
                                          std::vector<GlPassTime>* passes) const {
  static_assert(kNearestWords == 3);
  const uint32_t init[3] = {kFarDepthBits, 0u, 0u};
  glClearNamedBufferData(nearest, GL_RGB32UI, GL_RGB_INTEGER, GL_UNSIGNED_INT, init);
  const GLuint locks = fb.make("locks", uint64_t{pixels()} * 4);
  if (fb.failure) return *fb.failure;
  clearUint(locks, kLockFree);
  timedPass(passes, "nearest_normal", [&] {
    glUseProgram(program(ProgramId::NearestCosine));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBindNearest, nearest);
    fb.bindImage(locks, kBindLocks);
    drawScene();
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
  });
  if (const GLenum e = glGetError(); e != GL_NO_ERROR)
    return makeError("--engine gl: the nearest |n.v| pass failed (GL error " + glErrorText(e) +
                     ")");
  return {};
}

std::vector<float> GlEngine::State::readCosine(GLuint nearest) const {
  std::vector<uint32_t> words(uint64_t{pixels()} * kNearestWords);
  glGetNamedBufferSubData(nearest, 0, static_cast<GLsizeiptr>(words.size() * 4), words.data());
  std::vector<float> cosine(pixels());
  for (uint64_t p = 0; p < pixels(); ++p)
    cosine[p] = static_cast<float>(words[p * kNearestWords + 2]) / 255.0f;
  return cosine;
}

}  // namespace mfr::gl
