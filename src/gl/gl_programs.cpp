// The GL engine's program table and shader composition (gl_programs.hpp, shader_sources.hpp).
#include "gl/gl_programs.hpp"

#include <string_view>
#include <utility>
#include <vector>

#include "gl/shader_sources.hpp"
#include "mfr/core/result.hpp"

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

// `prelude`: lines after "#version" in the fragment shader (the interlock's #extension, #define);
// `raster`: the fragment stage's raster part (nullptr: none)
Result<GLuint> linkProgram(const std::string& name, const std::vector<StageFile>& stages,
                           const std::string& prelude = "", const char* raster = nullptr) {
  std::vector<GLuint> shaders;
  auto cleanup = [&] {
    for (GLuint s : shaders) glDeleteShader(s);
  };
  for (const StageFile& sf : stages) {
    const bool fragment = sf.stage == GL_FRAGMENT_SHADER;
    auto shader = compileShader(sf.stage, sf.file, fragment ? raster : nullptr,
                                fragment ? prelude : std::string());
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

Programs::~Programs() {
  for (GLuint p : ids_)
    if (p) glDeleteProgram(p);
}

Result<void> Programs::link(const GlContext& context, GlRaster raster,
                            const std::string& kbufferPrelude,
                            const std::function<void(GLuint)>& rasterUniforms) {
  const bool atomic64 = hasAtomic64(context);
  bool atomic64Linked = atomic64;
  for (const ProgramRow& row : kPrograms) {
    if (row.prelude == Prelude::Atomic64 && !atomic64) continue;
    std::string prelude;
    switch (row.prelude) {
      case Prelude::None:
        break;
      case Prelude::KBufferSync:
        prelude = kbufferPrelude;
        break;
      case Prelude::Atomic64:
        prelude = kAtomic64Prelude;
        break;
    }
    const bool isRaster = row.stages == Stages::Raster;
    std::vector<StageFile> stages = isRaster ? rasterStages(raster) : std::vector<StageFile>{};
    stages.push_back(
        {static_cast<GLenum>(isRaster ? GL_FRAGMENT_SHADER : GL_COMPUTE_SHADER), row.file});
    auto linked = linkProgram(row.file, stages, prelude, isRaster ? rasterPart(raster) : nullptr);
    if (!linked && row.prelude == Prelude::Atomic64) {
      atomic64Linked = false;
      continue;
    }
    if (!linked) return linked.error();
    ids_[static_cast<size_t>(row.id)] = *linked;
    if (isRaster) rasterUniforms(*linked);
  }
  if (!atomic64Linked)  // both atomic programs or neither
    for (ProgramId id : {ProgramId::KBufferAtomic64, ProgramId::SwapNodeWords}) {
      GLuint& p = ids_[static_cast<size_t>(id)];
      if (p) glDeleteProgram(p);
      p = 0;
    }
  return {};
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

std::vector<ShaderVariant> shaderVariants() {
  std::vector<ShaderVariant> out;
  const auto add = [&](const std::string& program, const std::string& file, const char* stage,
                       const char* raster, const std::string& prelude) {
    out.push_back({program, file, stage, composeSource(file, raster, prelude)});
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
    for (const auto& [variant, prelude] : preludes) {
      const std::string program = std::string(row.file) + variant;
      if (row.stages == Stages::Compute) {
        add(program, row.file, "comp", nullptr, prelude);
        continue;
      }
      for (const GlRaster raster : {GlRaster::Native, GlRaster::Exact}) {
        const std::string named = program + " [" + toString(raster) + "]";
        for (const StageFile& sf : rasterStages(raster))
          add(named, sf.file, sf.stage == GL_VERTEX_SHADER ? "vert" : "geom", nullptr, "");
        add(named, row.file, "frag", rasterPart(raster), prelude);
      }
    }
  }
  return out;
}

}  // namespace mfr::gl
