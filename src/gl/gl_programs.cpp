// The GL engine's program table and shader composition (gl_programs.hpp, shader_sources.hpp).
#include "gl/gl_programs.hpp"

#include <set>
#include <string_view>
#include <utility>
#include <vector>

#include "gl/shader_sources.hpp"
#include "mfr/core/result.hpp"
#include "mfr/gl/shared_layout.h"

namespace mfr::gl {
namespace {

// the fragment stage's raster part (raster_exact.glsl or raster_native.glsl)
const char* rasterPart(GlRaster raster) {
  switch (raster) {
    case GlRaster::Native:
      return "raster_native.glsl";
    case GlRaster::Exact:
      return "raster_exact.glsl";
  }
  return "raster_native.glsl";
}

struct StageFile {
  GLenum stage;
  std::string file;
};

// the vertex [and geometry] stages of a raster program
std::vector<StageFile> rasterStages(GlRaster raster) {
  switch (raster) {
    case GlRaster::Native:
      return {{GL_VERTEX_SHADER, "raster_native.vert"}};
    case GlRaster::Exact:
      return {{GL_VERTEX_SHADER, "raster.vert"}, {GL_GEOMETRY_SHADER, "raster.geom"}};
  }
  return {};
}

// "#version", the prelude, the shared layout, [a raster fragment stage's raster part and the
// common part,] the shader's own text
std::string composeSource(const std::string& file, const char* raster, const std::string& prelude) {
  std::string s = "#version 450 core\n";
  s += prelude;
  s += embeddedShader("shared_layout.h");
  s += "\n";
  s += embeddedShader("method_math.h");  // the methods' maths, shared with the CPU engine
  s += "\n";
  if (raster) {
    s += embeddedShader(raster);
    s += "\n";
    s += embeddedShader("raster_common.glsl");
    s += "\n";
  }
  s += "#line 1\n";
  s += embeddedShader(file);
  return s;
}

Result<GLuint> compileShader(GLenum stage, const std::string& file, const char* raster,
                             const std::string& prelude) {
  if (embeddedShader(file).empty()) return makeError("--engine gl: no embedded shader " + file);
  return compileShaderSource(stage, file, composeSource(file, raster, prelude));
}

// What a program's fragment stage is prefixed with.
enum class Prelude : uint8_t {
  None,
  KBufferSync,  // the k-buffer capture's sync: nothing (spin-lock) or the interlock extension
  Atomic64,     // GL_ARB_gpu_shader_int64 + GL_NV_shader_atomic_int64 (fixed-k 64-bit atomics)
};
// Raster: the raster stages of the engine's --gl-raster (rasterStages()) + this fragment shader;
// Compute: this compute shader alone.
enum class Stages : uint8_t { Raster, Compute };
struct ProgramRow {
  ProgramId id;
  const char* file;
  Stages stages;
  Prelude prelude;
};
// Every program of the engine, in link order (the first that fails is the error).
constexpr ProgramRow kPrograms[] = {
    {ProgramId::Count, "count.frag", Stages::Raster, Prelude::None},
    {ProgramId::ABuffer, "capture_abuffer.frag", Stages::Raster, Prelude::None},
    {ProgramId::KBuffer, "capture_kbuffer.frag", Stages::Raster, Prelude::KBufferSync},
    {ProgramId::KBufferAtomic64, "capture_kbuffer_atomic64.frag", Stages::Raster,
     Prelude::Atomic64},
    {ProgramId::SwapNodeWords, "swap_node_words.comp", Stages::Compute, Prelude::Atomic64},
    {ProgramId::DepthRange, "depth_range.frag", Stages::Raster, Prelude::None},
    {ProgramId::OccupancyFill, "occupancy_fill.frag", Stages::Raster, Prelude::None},
    {ProgramId::NearestCosine, "nearest_cosine.frag", Stages::Raster, Prelude::None},
    {ProgramId::Wboit, "wboit.frag", Stages::Raster, Prelude::None},
    {ProgramId::WboitResolve, "wboit_resolve.comp", Stages::Compute, Prelude::None},
    {ProgramId::Dfaoit, "dfaoit.frag", Stages::Raster, Prelude::None},
    {ProgramId::DfaoitResolve, "dfaoit_resolve.comp", Stages::Compute, Prelude::None},
    {ProgramId::MboitMoments, "mboit_moments.frag", Stages::Raster, Prelude::None},
    {ProgramId::MboitColor, "mboit_color.frag", Stages::Raster, Prelude::None},
    {ProgramId::MboitResolve, "mboit_resolve.comp", Stages::Compute, Prelude::None},
    {ProgramId::Mlab, "mlab.frag", Stages::Raster, Prelude::None},
    {ProgramId::MlabResolve, "mlab_resolve.comp", Stages::Compute, Prelude::None},
    {ProgramId::DkbFeatures, "dkb_features.frag", Stages::Raster, Prelude::None},
    {ProgramId::DkbInfer, "dkb_infer.comp", Stages::Compute, Prelude::None},
    {ProgramId::OccupancyCount, "occupancy_count.comp", Stages::Compute, Prelude::None},
    {ProgramId::PrefixSum, "prefix_sum.comp", Stages::Compute, Prelude::None},
    {ProgramId::PrefixSumAdd, "prefix_sum_add.comp", Stages::Compute, Prelude::None},
    {ProgramId::Resolve, "resolve.comp", Stages::Compute, Prelude::None},
    {ProgramId::AllocHistogram, "alloc_histogram.comp", Stages::Compute, Prelude::None},
    {ProgramId::Importance, "importance.comp", Stages::Compute, Prelude::None},
    {ProgramId::ImportanceTotal, "importance_total.comp", Stages::Compute, Prelude::None},
    {ProgramId::AllocK, "alloc_k.comp", Stages::Compute, Prelude::None},
    {ProgramId::AllocPack, "alloc_pack.comp", Stages::Compute, Prelude::None},
    {ProgramId::AoitVisibility, "aoit_visibility.frag", Stages::Raster, Prelude::None},
    {ProgramId::AoitColor, "aoit_color.frag", Stages::Raster, Prelude::None},
    {ProgramId::AoitResolve, "aoit_resolve.comp", Stages::Compute, Prelude::None},
    {ProgramId::ListCapture, "capture_list.frag", Stages::Raster, Prelude::None},
    {ProgramId::ListResolve, "resolve_list.comp", Stages::Compute, Prelude::None},
    {ProgramId::Peel, "peel.frag", Stages::Raster, Prelude::None},
    {ProgramId::PeelStep, "peel_step.comp", Stages::Compute, Prelude::None},
    {ProgramId::PeelResolve, "peel_resolve.comp", Stages::Compute, Prelude::None},
    {ProgramId::Stochastic, "stochastic.frag", Stages::Raster, Prelude::None},
    {ProgramId::StochasticResolve, "stochastic_resolve.comp", Stages::Compute, Prelude::None},
    {ProgramId::HashedAlpha, "hashed_alpha.frag", Stages::Raster, Prelude::None},
    {ProgramId::HashedAlphaResolve, "hashed_alpha_resolve.comp", Stages::Compute, Prelude::None},
};
constexpr bool rowsInIdOrder() {
  if (std::size(kPrograms) != kProgramCount) return false;
  for (size_t i = 0; i < kProgramCount; ++i)
    if (static_cast<size_t>(kPrograms[i].id) != i) return false;
  return true;
}
static_assert(rowsInIdOrder(), "kPrograms has one row per ProgramId, in its order");

constexpr const char* kAtomic64Prelude =
    "#extension GL_ARB_gpu_shader_int64 : require\n"
    "#extension GL_NV_shader_atomic_int64 : require\n";

// The k-buffer capture's prelude for a driver's interlock extension (empty: the spin-lock).
std::string interlockPrelude(const std::string& ext) {
  if (ext.empty()) return {};
  std::string prelude = "#extension " + ext + " : require\n";
  if (ext == "GL_ARB_fragment_shader_interlock")
    prelude +=
        "#define MFR_INTERLOCK_BEGIN() beginInvocationInterlockARB()\n"
        "#define MFR_INTERLOCK_END() endInvocationInterlockARB()\n";
  else if (ext == "GL_NV_fragment_shader_interlock")
    prelude +=
        "#define MFR_INTERLOCK_BEGIN() beginInvocationInterlockNV()\n"
        "#define MFR_INTERLOCK_END() endInvocationInterlockNV()\n";
  else  // the ordering lasts to the end of the shader
    prelude +=
        "#define MFR_INTERLOCK_BEGIN() beginFragmentShaderOrderingINTEL()\n"
        "#define MFR_INTERLOCK_END()\n";
  prelude += "#define MFR_INTERLOCK 1\n";
  if (ext != "GL_INTEL_fragment_shader_ordering")
    prelude += "layout(pixel_interlock_ordered) in;\n";
  return prelude;
}

// `prelude`: lines after "#version" in the program's own stage, the fragment or compute shader
// (the interlock's #extension, the switches' #defines); `raster`: the fragment stage's raster part
// (nullptr: none)
Result<GLuint> linkProgram(const std::string& name, const std::vector<StageFile>& stages,
                           const std::string& prelude = "", const char* raster = nullptr) {
  std::vector<GLuint> shaders;
  auto cleanup = [&] {
    for (GLuint s : shaders) glDeleteShader(s);
  };
  for (const StageFile& sf : stages) {
    const bool own = sf.stage == GL_FRAGMENT_SHADER || sf.stage == GL_COMPUTE_SHADER;
    auto shader =
        compileShader(sf.stage, sf.file, sf.stage == GL_FRAGMENT_SHADER ? raster : nullptr,
                      own ? prelude : std::string());
    if (!shader) {
      cleanup();
      return shader.error();
    }
    shaders.push_back(*shader);
  }
  const GLuint program = glCreateProgram();
  for (GLuint s : shaders) glAttachShader(program, s);
  glLinkProgram(program);
  cleanup();
  GLint ok = 0;
  glGetProgramiv(program, GL_LINK_STATUS, &ok);
  if (!ok) {
    GLint length = 0;
    glGetProgramiv(program, GL_INFO_LOG_LENGTH, &length);
    std::string log(static_cast<size_t>(std::max(length, 1)), '\0');
    glGetProgramInfoLog(program, length, nullptr, log.data());
    glDeleteProgram(program);
    return makeError("--engine gl: program " + name + " does not link: " + oneLine(log.c_str()));
  }
  return program;
}

// "#define NAME VALUE\n"
std::string defineLine(const char* name, uint32_t value) {
  return "#define " + std::string(name) + " " + std::to_string(value) + "\n";
}

const ProgramRow& rowOf(ProgramId id) {
  return kPrograms[static_cast<size_t>(id)];
}

}  // namespace

std::string oneLine(std::string text) {
  while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
  std::string out;
  for (char c : text) {
    if (c == '\n')
      out += " | ";
    else
      out += c;
  }
  return out;
}

std::string EngineSwitches::prelude() const {
  return defineLine("MFR_SAMPLES", static_cast<uint32_t>(samples)) +
         defineLine("MFR_SAMPLE_STORAGE", sampleStorage ? 1 : 0) +
         defineLine("MFR_VERTEX_COLORS", vertexColors ? 1 : 0) +
         defineLine("MFR_TEXTURES", textures ? 1 : 0) +
         defineLine("MFR_ALPHA_MASK", alphaMask ? 1 : 0) + "#define MFR_BLEND_MODES " +
         std::to_string(blendModes) + "u\n";
}

std::string kbufferSwitches(bool perPixel, uint32_t store, bool occupancy, bool hybrid) {
  return defineLine("MFR_PER_PIXEL", perPixel ? 1 : 0) +
         defineLine("MFR_STORE", perPixel ? kStoreMaxArray : store) +
         defineLine("MFR_OCCUPANCY", occupancy ? 1 : 0) + defineLine("MFR_HYBRID", hybrid ? 1 : 0);
}

std::string resolveSwitches(uint32_t nodes, bool hybrid, bool localSort, bool writeSorted) {
  return defineLine("MFR_RESOLVE_NODES", nodes) + defineLine("MFR_HYBRID", hybrid ? 1 : 0) +
         defineLine("MFR_LOCAL_SORT", localSort ? 1 : 0) +
         defineLine("MFR_WRITE_SORTED", writeSorted ? 1 : 0);
}

std::string mboitSwitches(uint32_t moments, bool trigonometric, bool quantized) {
  return defineLine("MFR_MOMENTS", moments) +
         defineLine("MFR_TRIGONOMETRIC", trigonometric ? 1 : 0) +
         defineLine("MFR_QUANTIZED", quantized ? 1 : 0);
}

std::string aoitSwitches(uint32_t nodes) {
  return defineLine("MFR_AOIT_NODES", nodes);
}

std::string stochasticSwitches(uint32_t pass, bool stratified) {
  return defineLine("MFR_PASS", pass) + defineLine("MFR_STRATIFIED", stratified ? 1 : 0);
}

std::string peelSwitches(bool dual, bool tail) {
  return defineLine("MFR_DUAL", dual ? 1 : 0) + defineLine("MFR_TAIL", tail ? 1 : 0);
}

std::string peelStepSwitches(bool dual) {
  return defineLine("MFR_DUAL", dual ? 1 : 0);
}

std::string peelResolveSwitches(bool dual, bool hybrid) {
  return defineLine("MFR_DUAL", dual ? 1 : 0) + defineLine("MFR_HYBRID", hybrid ? 1 : 0);
}

std::string listSwitches(bool hybrid) {
  return defineLine("MFR_HYBRID", hybrid ? 1 : 0);
}

Programs::~Programs() {
  for (GLuint p : ids_)
    if (p) glDeleteProgram(p);
  for (const auto& [key, p] : variants_) glDeleteProgram(p);
}

Result<GLuint> Programs::linkRow(ProgramId id, const std::string& defines) const {
  const ProgramRow& row = rowOf(id);
  std::string prelude;
  switch (row.prelude) {  // the #extension lines first
    case Prelude::None:
      break;
    case Prelude::KBufferSync:
      prelude = kbufferPrelude_;
      break;
    case Prelude::Atomic64:
      prelude = kAtomic64Prelude;
      break;
  }
  prelude += enginePrelude_ + defines;
  const bool isRaster = row.stages == Stages::Raster;
  std::vector<StageFile> stages = isRaster ? rasterStages(raster_) : std::vector<StageFile>{};
  stages.push_back(
      {static_cast<GLenum>(isRaster ? GL_FRAGMENT_SHADER : GL_COMPUTE_SHADER), row.file});
  auto linked = linkProgram(row.file, stages, prelude, isRaster ? rasterPart(raster_) : nullptr);
  if (linked && isRaster) rasterUniforms_(*linked);
  return linked;
}

Result<void> Programs::link(const GlContext& context, GlRaster raster,
                            const std::string& kbufferPrelude, const EngineSwitches& switches,
                            const std::function<void(GLuint)>& rasterUniforms) {
  raster_ = raster;
  kbufferPrelude_ = kbufferPrelude;
  enginePrelude_ = switches.prelude();
  rasterUniforms_ = rasterUniforms;
  const bool atomic64 = hasAtomic64(context);
  bool atomic64Linked = atomic64;
  for (const ProgramRow& row : kPrograms) {
    if (row.prelude == Prelude::Atomic64 && !atomic64) continue;
    auto linked = linkRow(row.id, "");
    if (!linked && row.prelude == Prelude::Atomic64) {
      atomic64Linked = false;
      continue;
    }
    if (!linked) return linked.error();
    ids_[static_cast<size_t>(row.id)] = *linked;
  }
  if (!atomic64Linked)  // both atomic programs or neither
    for (ProgramId id : {ProgramId::KBufferAtomic64, ProgramId::SwapNodeWords}) {
      GLuint& p = ids_[static_cast<size_t>(id)];
      if (p) glDeleteProgram(p);
      p = 0;
    }
  return {};
}

Result<GLuint> Programs::variant(ProgramId id, const std::string& defines) {
  if (defines.empty()) return (*this)[id];
  const auto key = std::make_pair(id, defines);
  if (const auto it = variants_.find(key); it != variants_.end()) return it->second;
  auto linked = linkRow(id, defines);
  if (!linked) return linked.error();
  variants_.emplace(key, *linked);
  return *linked;
}

Result<std::string> kbufferInterlockPrelude(const GlContext& context, bool interlock) {
  if (!interlock) return std::string();
  const std::string ext = interlockExtension(context);
  if (ext.empty())
    return makeError(
        "--gl-sync interlock: the driver offers none of GL_ARB_fragment_shader_interlock, "
        "GL_NV_fragment_shader_interlock, GL_INTEL_fragment_shader_ordering");
  return interlockPrelude(ext);
}

Result<unsigned> compileShaderSource(unsigned stage, const std::string& name,
                                     const std::string& source) {
  const GLuint shader = glCreateShader(stage);
  if (shader == 0) return makeError("--engine gl: shader " + name + ": glCreateShader failed");
  const char* text = source.c_str();
  glShaderSource(shader, 1, &text, nullptr);
  glCompileShader(shader);
  GLint ok = 0;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    GLint length = 0;
    glGetShaderiv(shader, GL_INFO_LOG_LENGTH, &length);
    std::string log(static_cast<size_t>(std::max(length, 1)), '\0');
    glGetShaderInfoLog(shader, length, nullptr, log.data());
    glDeleteShader(shader);
    return makeError("--engine gl: shader " + name + " does not compile: " + oneLine(log.c_str()));
  }
  return shader;
}

bool hasAtomic64(const GlContext& context) {
  return context.extensions().arbGpuShaderInt64 && context.extensions().nvShaderAtomicInt64;
}

std::string interlockExtension(const GlContext& context) {
  const GlExtensions& e = context.extensions();
  if (e.arbFragmentShaderInterlock) return "GL_ARB_fragment_shader_interlock";
  if (e.nvFragmentShaderInterlock) return "GL_NV_fragment_shader_interlock";
  if (e.intelFragmentShaderOrdering) return "GL_INTEL_fragment_shader_ordering";
  return {};
}

namespace {

// The engine switches a raster validates under: the defaults (one sample, every feature), none
// of the scene's features, and, natively, four samples in each storage discipline.
std::vector<EngineSwitches> engineSwitchSets(GlRaster raster) {
  EngineSwitches none;
  none.vertexColors = none.textures = none.alphaMask = false;
  none.blendModes = 1u << kBlendOver;
  std::vector<EngineSwitches> sets = {EngineSwitches{}, none};
  if (raster == GlRaster::Native)
    for (const bool storage : {false, true}) {
      EngineSwitches multi;
      multi.samples = 4;
      multi.sampleStorage = storage;
      sets.push_back(multi);
    }
  return sets;
}

// Each program's own switch sets (its Programs::variant defines, built by the *Switches
// functions above), every combination; one empty set for a program without switches.
std::vector<std::string> programSwitchSets(ProgramId id) {
  std::vector<std::string> sets;
  switch (id) {
    case ProgramId::KBuffer:
      for (const bool occupancy : {false, true})
        for (const bool hybrid : {false, true}) {
          sets.push_back(kbufferSwitches(true, kStoreMaxArray, occupancy, hybrid));
          for (const uint32_t store : {kStoreMaxArray, kStoreMaxHeap})
            sets.push_back(kbufferSwitches(false, store, occupancy, hybrid));
        }
      break;
    case ProgramId::Resolve:
      for (const uint32_t nodes : {kResolveFixedK, kResolveABuffer, kResolvePerPixel})
        for (const bool hybrid : {false, true})
          for (const bool local : {false, true})
            for (const bool write : {false, true})
              sets.push_back(resolveSwitches(nodes, hybrid, local, write));
      break;
    case ProgramId::MboitMoments:
    case ProgramId::MboitColor:
      for (const uint32_t moments : {4u, 6u, 8u})
        for (const bool trigonometric : {false, true})
          for (const bool quantized : {false, true})
            sets.push_back(mboitSwitches(moments, trigonometric, quantized));
      break;
    case ProgramId::AoitVisibility:
    case ProgramId::AoitColor:
    case ProgramId::AoitResolve:
      for (const uint32_t nodes : {4u, 8u, 16u}) sets.push_back(aoitSwitches(nodes));
      break;
    case ProgramId::Stochastic:
      for (const uint32_t pass : {0u, 1u, 2u})
        for (const bool stratified : {false, true})
          sets.push_back(stochasticSwitches(pass, stratified));
      break;
    case ProgramId::Peel:
      for (const bool dual : {false, true})
        for (const bool tail : {false, true}) sets.push_back(peelSwitches(dual, tail));
      break;
    case ProgramId::PeelStep:
      for (const bool dual : {false, true}) sets.push_back(peelStepSwitches(dual));
      break;
    case ProgramId::PeelResolve:
      for (const bool dual : {false, true})
        for (const bool hybrid : {false, true}) sets.push_back(peelResolveSwitches(dual, hybrid));
      break;
    case ProgramId::ListCapture:
    case ProgramId::ListResolve:
      for (const bool hybrid : {false, true}) sets.push_back(listSwitches(hybrid));
      break;
    default:
      sets.push_back("");
  }
  return sets;
}

}  // namespace

std::vector<ShaderVariant> shaderVariants() {
  std::vector<ShaderVariant> out;
  std::set<std::string> seen;  // stages without a prelude are the same text in every variant
  const auto add = [&](const std::string& program, const std::string& file, const char* stage,
                       const char* raster, const std::string& prelude) {
    std::string source = composeSource(file, raster, prelude);
    if (!seen.insert(std::string(stage) + "\n" + source).second) return;
    out.push_back({program, file, stage, std::move(source)});
  };
  for (const ProgramRow& row : kPrograms) {
    std::vector<std::pair<std::string, std::string>> preludes;  // variant name, prelude
    switch (row.prelude) {
      case Prelude::None:
        preludes = {{"", ""}};
        break;
      case Prelude::KBufferSync:
        preludes = {{" (lock)", ""}};
        for (const char* ext :
             {"GL_ARB_fragment_shader_interlock", "GL_NV_fragment_shader_interlock",
              "GL_INTEL_fragment_shader_ordering"})
          preludes.push_back({std::string(" (") + ext + ")", interlockPrelude(ext)});
        break;
      case Prelude::Atomic64:
        preludes = {{" (64-bit atomics)", kAtomic64Prelude}};
        break;
    }
    const std::vector<std::string> switchSets = programSwitchSets(row.id);
    for (const auto& [variant, prelude] : preludes) {
      const std::string program = std::string(row.file) + variant;
      if (row.stages == Stages::Compute) {
        for (const EngineSwitches& engine : engineSwitchSets(GlRaster::Native))
          for (const std::string& switches : switchSets)
            add(program, row.file, "comp", nullptr, prelude + engine.prelude() + switches);
        continue;
      }
      for (const GlRaster raster : {GlRaster::Native, GlRaster::Exact}) {
        const std::string named = program + " [" + toString(raster) + "]";
        for (const StageFile& sf : rasterStages(raster))
          add(named, sf.file, sf.stage == GL_VERTEX_SHADER ? "vert" : "geom", nullptr, "");
        for (const EngineSwitches& engine : engineSwitchSets(raster))
          for (const std::string& switches : switchSets)
            add(named, row.file, "frag", rasterPart(raster), prelude + engine.prelude() + switches);
      }
    }
  }
  return out;
}

}  // namespace mfr::gl
