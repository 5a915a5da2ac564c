// The OpenGL engine against the CPU engine (the reference), per pixel: n(p), the A-buffer's and the
// fixed-k k-buffer's captured nodes, the images; and GL runs repeat byte for byte. Without a GL 4.5
// core context the tests skip, except under CI=true, where they fail.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "../shared_scenes.hpp"
#include "gl/shader_sources.hpp"
#include "mfr/cpu/raster_frame.hpp"
#include "mfr/cpu/render.hpp"
#include "mfr/gl/gl_context.hpp"
#include "mfr/gl/gl_engine.hpp"
#include "mfr/method/method.hpp"
#include "mfr/scene/load.hpp"

namespace mfr::gl {
namespace {

const Result<GlContext>& sharedContext() {
  static const auto* context = new Result<GlContext>(GlContext::create());
  return *context;
}

bool requireContextFails() {
  const char* ci = std::getenv("CI");
  return ci != nullptr && std::string(ci) == "true";
}

#define MFR_REQUIRE_GL()                                                    \
  do {                                                                      \
    if (!sharedContext().ok()) {                                            \
      if (requireContextFails()) FAIL() << sharedContext().error().message; \
      GTEST_SKIP() << sharedContext().error().message;                      \
    }                                                                       \
  } while (0)

const glm::vec3 kBackground(0.25f, 0.5f, 0.75f);

struct Case {
  std::string scene;
  int width, height;
};

void PrintTo(const Case& c, std::ostream* os) {
  *os << c.scene << " " << c.width << "x" << c.height;
}

std::string caseName(const testing::TestParamInfo<Case>& info) {
  std::string s = info.param.scene.substr(info.param.scene.find(':') + 1);
  return s + "_" + std::to_string(info.param.width) + "x" + std::to_string(info.param.height);
}

void compareNodes(const RenderOutput& cpu, const GlRenderOutput& gl, int width) {
  const size_t pixels = cpu.counts.size();
  ASSERT_EQ(gl.nodeCounts.size(), pixels);
  size_t identical = 0, depthOnly = 0, different = 0, nodes = 0;
  for (size_t p = 0; p < pixels; ++p) {
    std::vector<FragmentNode> a(
        cpu.nodes.begin() + static_cast<ptrdiff_t>(cpu.offsets[p]),
        cpu.nodes.begin() + static_cast<ptrdiff_t>(cpu.offsets[p] + cpu.counts[p]));
    std::vector<FragmentNode> b(
        gl.nodes.begin() + static_cast<ptrdiff_t>(gl.nodeOffsets[p]),
        gl.nodes.begin() + static_cast<ptrdiff_t>(gl.nodeOffsets[p] + gl.nodeCounts[p]));
    std::sort(a.begin(), a.end());
    ASSERT_TRUE(std::is_sorted(b.begin(), b.end())) << "pixel " << p;
    nodes += a.size();
    if (a == b) {
      ++identical;
      continue;
    }
    bool close = a.size() == b.size();
    for (size_t i = 0; close && i < a.size(); ++i) {
      const float da = nodeDepth(a[i]), db = nodeDepth(b[i]);
      close = nodeColor(a[i]) == nodeColor(b[i]) &&
              std::fabs(da - db) <= 1e-6f * std::max(std::fabs(da), 1e-30f);
    }
    if (close) {
      ++depthOnly;
    } else {
      if (different < 10)
        std::cout << "  nodes differ at pixel (" << p % width << ", " << p / width << "): CPU "
                  << a.size() << ", GL " << b.size() << "\n";
      ++different;
    }
  }
  std::cout << "  nodes: " << nodes << " CPU nodes; pixels identical " << identical
            << ", depth within 1e-6 " << depthOnly << ", different " << different << " of "
            << pixels << "\n";
  EXPECT_EQ(different, 0u);
}

void compareImages(const ImageRGB& cpu, const ImageRGB& gl) {
  ASSERT_EQ(cpu.pixels.size(), gl.pixels.size());
  float maxDiff = 0.0f;
  size_t exact = 0;
  for (size_t i = 0; i < cpu.pixels.size(); ++i) {
    const glm::vec3 d = glm::abs(cpu.pixels[i] - gl.pixels[i]);
    maxDiff = std::max({maxDiff, d.r, d.g, d.b});
    exact += cpu.pixels[i] == gl.pixels[i];
  }
  std::cout << "  image: max |CPU - GL| " << maxDiff << " (linear), pixels bit-identical " << exact
            << " of " << cpu.pixels.size() << "\n";
  EXPECT_LE(maxDiff, 1.0f / 255.0f);
}

class GlVsCpu : public testing::TestWithParam<Case> {
 protected:
  void SetUp() override {
    MFR_REQUIRE_GL();
    auto scene = loadScene(GetParam().scene);
    ASSERT_TRUE(scene.ok()) << scene.error().message;
    scene_ = std::make_unique<Scene>(std::move(scene.value()));
    camera_ = *scene_->defaultCamera;
    auto frame = RasterFrame::build(*scene_, camera_,
                                    RasterOptions{GetParam().width, GetParam().height, 16, 0});
    ASSERT_TRUE(frame.ok()) << frame.error().message;
    frame_ = std::make_unique<RasterFrame>(std::move(frame.value()));
    auto engine = GlEngine::create(sharedContext().value(), *scene_, camera_, GetParam().width,
                                   GetParam().height, false, GlRaster::Exact);
    ASSERT_TRUE(engine.ok()) << engine.error().message;
    engine_ = std::make_unique<GlEngine>(std::move(engine.value()));
  }

  RenderOutput cpuRender(const MethodDesc& method) const {
    RenderOptions options;
    options.keepStores = true;
    options.background = kBackground;
    auto out = render(*frame_, method, options);
    EXPECT_TRUE(out.ok()) << out.error().message;
    return std::move(out.value());
  }

  GlRenderOutput glRender(const MethodDesc& method) const {
    GlRenderOptions options;
    options.background = kBackground;
    options.readNodes = true;
    options.warmUp = false;  // (pass times printed by these tests are cold)
    auto out = engine_->render(method, options);
    EXPECT_TRUE(out.ok()) << out.error().message;
    return std::move(out.value());
  }

  // Same captured node set per pixel (the CPU stores are unsorted; GL's are sorted by the
  // resolve). Returns the pixels whose sets differ.
  void expectSameNodes(const RenderOutput& cpu, const GlRenderOutput& gl) const {
    compareNodes(cpu, gl, frame_->width());
  }
  void expectSameImage(const ImageRGB& cpu, const ImageRGB& gl) const { compareImages(cpu, gl); }

  static void printPasses(const GlRenderOutput& gl) {
    std::cout << "  GL passes (cold):";
    for (const GlPassTime& t : gl.passes)
      std::cout << " " << t.name << " " << t.gpuMs << " ms (wall " << t.wallMs << ")";
    std::cout << "; buffers " << gl.totalBufferBytes() << " B\n";
  }

  std::unique_ptr<Scene> scene_;
  Camera camera_;
  std::unique_ptr<RasterFrame> frame_;
  std::unique_ptr<GlEngine> engine_;
};

TEST_P(GlVsCpu, CountsEqualTheCpuCountPass) {
  const std::vector<uint32_t> cpu = countFragments(*frame_);
  const GlRenderOutput gl = glRender(methodPreset("abuffer").value());
  ASSERT_EQ(gl.counts.size(), cpu.size());
  size_t covered = 0, differ = 0;
  uint64_t fragments = 0;
  for (size_t p = 0; p < cpu.size(); ++p) {
    covered += cpu[p] > 0 || gl.counts[p] > 0;
    fragments += cpu[p];
    if (cpu[p] != gl.counts[p]) {
      if (differ < 20)
        std::cout << "  pixel (" << p % frame_->width() << ", " << p / frame_->width()
                  << "): CPU n " << cpu[p] << ", GL n " << gl.counts[p] << "\n";
      ++differ;
    }
  }
  std::cout << "  n(p): " << fragments << " fragments, " << covered << " covered pixels, " << differ
            << " differ\n";
  EXPECT_GT(fragments, 0u);
  EXPECT_LE(differ * 10000, covered);  // <= 0.01% of covered pixels
  EXPECT_EQ(gl.fragments, fragments);
}

TEST_P(GlVsCpu, ABufferNodesAndImageEqualTheCpuEngine) {
  const MethodDesc method = methodPreset("abuffer").value();
  const RenderOutput cpu = cpuRender(method);
  const GlRenderOutput gl = glRender(method);
  expectSameNodes(cpu, gl);
  expectSameImage(cpu.image, gl.image);
  printPasses(gl);
}

TEST_P(GlVsCpu, KBufferK4NodesAndImageEqualTheCpuKPlusArray) {
  MethodDesc method = methodPreset("kplus-array").value();
  method.k = 4;
  const RenderOutput cpu = cpuRender(method);
  const GlRenderOutput gl = glRender(method);
  expectSameNodes(cpu, gl);
  expectSameImage(cpu.image, gl.image);
  printPasses(gl);
}

TEST_P(GlVsCpu, KBufferHeapK5NodesAndImageEqualTheCpuKPlusHeap) {
  MethodDesc method = methodPreset("kplus-heap").value();
  method.k = 5;
  const RenderOutput cpu = cpuRender(method);
  const GlRenderOutput gl = glRender(method);
  expectSameNodes(cpu, gl);
  expectSameImage(cpu.image, gl.image);
  printPasses(gl);
}

// The fixed-k capture's synchronisation is chosen at run time: 64-bit atomicMin where the driver
// has GL_NV_shader_atomic_int64 (a tail or occupancy culling keeps the lock), else the spin-lock;
// either way the CPU engine's nearest sets and image. llvmpipe has no 64-bit atomics: there it
// checks that the lock is taken and the atomic variant is not compiled.
TEST_P(GlVsCpu, FixedKCaptureWithAtomic64WhereOfferedElseTheLock) {
  const bool offered = hasAtomic64(sharedContext().value());
  for (const char* preset : {"kplus-array", "kplus-heap", "kplus-array+occupancy"}) {
    SCOPED_TRACE(preset);
    MethodDesc method = methodPreset(preset).value();
    method.k = 3;
    const RenderOutput cpu = cpuRender(method);
    const GlRenderOutput gl = glRender(method);
    EXPECT_EQ(gl.atomic64, offered && method.occupancyWords == 0);
    expectSameNodes(cpu, gl);
    expectSameImage(cpu.image, gl.image);
  }
  MethodDesc hybrid = methodPreset("kplus-array").value();
  hybrid.k = 3;
  hybrid.compositing = Compositing::Hybrid;
  EXPECT_FALSE(glRender(hybrid).atomic64);
  if (!offered)
    std::cout << "  " << sharedContext()->renderer()
              << ": no GL_NV_shader_atomic_int64, the fixed-k capture takes the lock\n";
}

// Occupancy culling (d = 1 and 2 words): the same nearest sets, and since the maps and the test
// do not depend on arrival order, the same number of fragments culled by the occupancy test.
TEST_P(GlVsCpu, OccupancyCullingEqualsTheCpuEngine) {
  for (const char* preset : {"kplus-array+occupancy", "kplus-heap+occupancy"}) {
    MethodDesc method = methodPreset(preset).value();
    method.k = 4;
    method.occupancyWords = std::string(preset) == "kplus-heap+occupancy" ? 2 : 1;
    const RenderOutput cpu = cpuRender(method);
    const GlRenderOutput gl = glRender(method);
    std::cout << "  " << preset << " d=" << method.occupancyWords << ": culled by occupancy CPU "
              << cpu.stats.culledOccupancy << ", GL " << gl.culledOccupancy << "; by k+ CPU "
              << cpu.stats.culledKPlus << ", GL " << gl.culledKPlus << "\n";
    EXPECT_EQ(gl.culledOccupancy, cpu.stats.culledOccupancy) << preset;
    EXPECT_GT(gl.culledOccupancy, 0u) << preset;
    expectSameNodes(cpu, gl);
    expectSameImage(cpu.image, gl.image);
    printPasses(gl);
  }
}

// Hybrid compositing (DHOIT sec. 3.3) with k = 4: the culled, rejected and evicted fragments go to
// each pixel's tail. The tails are float sums in arrival order, and GLSL's pow is not std::pow, so
// the images agree within 1/255 (not necessarily bit for bit); the cores are the same sets.
TEST_P(GlVsCpu, HybridK4EqualsTheCpuEngine) {
  for (const char* preset : {"kplus-array", "kplus-heap+occupancy"}) {
    MethodDesc method = methodPreset(preset).value();
    method.k = 4;
    method.compositing = Compositing::Hybrid;
    const RenderOutput cpu = cpuRender(method);
    const GlRenderOutput gl = glRender(method);
    std::cout << "  " << preset << " hybrid:\n";
    expectSameNodes(cpu, gl);
    expectSameImage(cpu.image, gl.image);
    printPasses(gl);
  }
}

TEST_P(GlVsCpu, ThreeRunsAreByteIdentical) {
  for (const char* preset : {"abuffer", "kplus-array"}) {
    MethodDesc method = methodPreset(preset).value();
    if (std::string(preset) != "abuffer") method.k = 4;
    const GlRenderOutput first = glRender(method);
    for (int run = 0; run < 2; ++run) {
      const GlRenderOutput again = glRender(method);
      EXPECT_EQ(first.counts, again.counts) << preset;
      EXPECT_EQ(first.nodes, again.nodes) << preset;
      ASSERT_EQ(first.image.pixels.size(), again.image.pixels.size());
      EXPECT_EQ(std::memcmp(first.image.pixels.data(), again.image.pixels.data(),
                            first.image.pixels.size() * sizeof(glm::vec3)),
                0)
          << preset;
    }
  }
}

// A frame takes the buffers of the engine's previous frame (BufferPool): whatever another method
// left in them, the frame is the one a fresh engine renders.
TEST_P(GlVsCpu, FrameAfterOtherMethodsEqualsAFreshEngines) {
  MethodDesc method = methodPreset("kplus-array").value();
  method.k = 4;
  const GlRenderOutput first = glRender(method);
  MethodDesc hybrid = methodPreset("kplus-heap+occupancy").value();
  hybrid.k = 4;
  hybrid.compositing = Compositing::Hybrid;
  for (const MethodDesc& other : {hybrid, methodPreset("abuffer").value()}) {
    glRender(other);
    const GlRenderOutput again = glRender(method);
    EXPECT_EQ(first.counts, again.counts) << other.name;
    EXPECT_EQ(first.nodes, again.nodes) << other.name;
    ASSERT_EQ(first.image.pixels.size(), again.image.pixels.size());
    EXPECT_EQ(std::memcmp(first.image.pixels.data(), again.image.pixels.data(),
                          first.image.pixels.size() * sizeof(glm::vec3)),
              0)
        << other.name;
  }
  // and the hybrid frame after them equals the CPU engine's
  const RenderOutput cpu = cpuRender(hybrid);
  const GlRenderOutput gl = glRender(hybrid);
  expectSameNodes(cpu, gl);
  expectSameImage(cpu.image, gl.image);
}

INSTANTIATE_TEST_SUITE_P(Scenes, GlVsCpu,
                         testing::Values(Case{"procedural:layers", 128, 128},
                                         Case{"procedural:layers", 131, 97},
                                         Case{"procedural:hairball", 128, 128},
                                         Case{"procedural:hairball", 131, 97}),
                         caseName);

// Overlapping tilted quads with a small RGBA texture (uvs beyond [0, 1] and negative: repeat
// wrapping), Blend, Mask (alpha test on the texture's alpha) and Opaque materials: the texture
// sampling and alpha test paths, which the procedural scenes do not use.
Scene texturedQuads(std::optional<float> alphaOverride) {
  Scene s;
  s.name = "textured quads";
  Texture t;
  t.width = 7;
  t.height = 5;
  for (int y = 0; y < t.height; ++y)
    for (int x = 0; x < t.width; ++x) {
      t.rgba.push_back(static_cast<uint8_t>((x * 37 + y * 11) % 256));
      t.rgba.push_back(static_cast<uint8_t>((x * 5 + y * 71) % 256));
      t.rgba.push_back(static_cast<uint8_t>((x * 93 + y * 29) % 256));
      t.rgba.push_back(static_cast<uint8_t>((x + y) % 3 == 0 ? 20 : 40 + 50 * ((x * y) % 5)));
    }
  s.textures.push_back(t);
  Material blend;
  blend.baseColor = {0.9f, 0.8f, 0.7f, 0.6f};
  blend.baseColorTexture = 0;
  blend.alphaMode = AlphaMode::Blend;
  Material mask;
  mask.baseColor = {1.0f, 0.9f, 1.0f, 1.0f};
  mask.baseColorTexture = 0;
  mask.alphaMode = AlphaMode::Mask;
  mask.alphaCutoff = 0.45f;
  Material opaque;
  opaque.baseColor = {0.2f, 0.6f, 0.3f, 1.0f};
  opaque.alphaMode = AlphaMode::Opaque;
  s.materials = {blend, mask, opaque};
  for (int q = 0; q < 6; ++q) {
    const float z = -0.35f * static_cast<float>(q), dx = 0.13f * static_cast<float>(q) - 0.3f;
    const float tilt = 0.2f * static_cast<float>(q % 3) - 0.2f;
    const uint32_t base = static_cast<uint32_t>(s.positions.size());
    const glm::vec2 corners[4] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
    for (const glm::vec2& c : corners) {
      s.positions.push_back({c.x + dx, c.y * 0.8f, z + tilt * c.x});
      s.normals.push_back(glm::normalize(glm::vec3(-tilt + 0.1f * c.y, 0.15f * c.x, 1.0f)));
      s.uvs.push_back({(c.x + 1.0f) * 1.9f - 1.3f, (c.y + 1.0f) * 1.6f - 0.7f});
    }
    for (uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) s.indices.push_back(base + i);
    s.triangleMaterial.push_back(static_cast<uint32_t>(q % 3));
    s.triangleMaterial.push_back(static_cast<uint32_t>(q % 3));
  }
  Camera camera;
  camera.eye = {0.4f, 0.5f, 3.0f};
  camera.target = {0.0f, 0.0f, -0.8f};
  camera.fovYDegrees = 50.0f;
  s.defaultCamera = camera;
  s.alphaOverride = alphaOverride;
  return s;
}

TEST(GlEngine, TexturedMaskedQuadsEqualTheCpuEngine) {
  MFR_REQUIRE_GL();
  for (std::optional<float> alphaOverride : {std::optional<float>(), std::optional<float>(0.5f)}) {
    const Scene scene = texturedQuads(alphaOverride);
    const int width = 101, height = 67;
    auto frame =
        RasterFrame::build(scene, *scene.defaultCamera, RasterOptions{width, height, 16, 0});
    ASSERT_TRUE(frame.ok()) << frame.error().message;
    auto engine = GlEngine::create(sharedContext().value(), scene, *scene.defaultCamera, width,
                                   height, false, GlRaster::Exact);
    ASSERT_TRUE(engine.ok()) << engine.error().message;
    const MethodDesc method = methodPreset("abuffer").value();
    RenderOptions cpuOptions;
    cpuOptions.keepStores = true;
    cpuOptions.background = kBackground;
    auto cpu = render(*frame, method, cpuOptions);
    ASSERT_TRUE(cpu.ok()) << cpu.error().message;
    GlRenderOptions glOptions;
    glOptions.background = kBackground;
    glOptions.readNodes = true;
    glOptions.warmUp = false;
    auto gl = engine->render(method, glOptions);
    ASSERT_TRUE(gl.ok()) << gl.error().message;
    EXPECT_EQ(gl->counts, countFragments(*frame));
    EXPECT_GT(gl->fragments, 5000u);
    compareNodes(*cpu, *gl, width);
    compareImages(cpu->image, gl->image);
  }
}

// An A-buffer larger than one shader storage block is an error naming the limit, not a silently
// clamped buffer (llvmpipe: 128 MiB; procedural:layers at 768x768 needs about 300 MB of nodes).
TEST(GlEngine, ABufferAboveTheStorageBlockLimitIsAnError) {
  MFR_REQUIRE_GL();
  auto scene = loadScene("procedural:layers");
  ASSERT_TRUE(scene.ok());
  auto engine = GlEngine::create(sharedContext().value(), *scene, *scene->defaultCamera, 768, 768,
                                 false, GlRaster::Exact);
  ASSERT_TRUE(engine.ok()) << engine.error().message;
  GlRenderOptions options;
  options.warmUp = false;
  auto out = engine->render(methodPreset("abuffer").value(), options);
  if (out.ok()) {
    EXPECT_GT(out->fragments * 8, uint64_t{128} << 20);  // a larger limit: it fits
  } else {
    EXPECT_NE(out.error().message.find("GL_MAX_SHADER_STORAGE_BLOCK_SIZE"), std::string::npos)
        << out.error().message;
    std::cout << "  " << out.error().message << "\n";
  }
}

// A buffer GL cannot allocate (far beyond any memory and GL_MAX_SHADER_STORAGE_BLOCK_SIZE): one
// line naming the buffer and its bytes, no GL error left pending; a small one succeeds.
TEST(GlEngine, OutOfMemoryNamesTheBufferAndItsBytes) {
  MFR_REQUIRE_GL();
  sharedContext()->makeCurrent();
  const uint64_t huge = uint64_t{1} << 46;  // 64 TiB
  auto b = createCheckedBuffer("test nodes", huge);
  ASSERT_FALSE(b.ok());
  const std::string& m = b.error().message;
  EXPECT_EQ(m.find("--engine gl: out of GPU memory: the test nodes buffer (" +
                   std::to_string(huge) + " B)"),
            0u)
      << m;
  EXPECT_EQ(m.find('\n'), std::string::npos) << m;
  std::cout << "  " << m << "\n";
  auto small = createCheckedBuffer("small", 1024);
  ASSERT_TRUE(small.ok()) << small.error().message;
  // the engine still renders afterwards
  auto scene = loadScene("procedural:layers");
  ASSERT_TRUE(scene.ok());
  auto engine = GlEngine::create(sharedContext().value(), *scene, *scene->defaultCamera, 16, 16,
                                 false, GlRaster::Exact);
  ASSERT_TRUE(engine.ok()) << engine.error().message;
  EXPECT_TRUE(engine->render(methodPreset("abuffer").value()).ok());
}

TEST(GlEngine, ShaderCompileErrorNamesTheShaderAndCarriesItsLog) {
  MFR_REQUIRE_GL();
  auto shader = compileShaderSource(0x8B30 /* GL_FRAGMENT_SHADER */, "broken.frag",
                                    "#version 450 core\nvoid main() { undeclaredThing = 1.0; }\n");
  ASSERT_FALSE(shader.ok());
  const std::string& message = shader.error().message;
  EXPECT_NE(message.find("broken.frag"), std::string::npos) << message;
  EXPECT_NE(message.find("undeclaredThing"), std::string::npos) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  std::cout << "  " << message << "\n";
  // every embedded shader is there and the shared layout with it
  for (const char* name :
       {"raster.vert", "raster.geom", "raster_common.glsl", "count.frag", "capture_abuffer.frag",
        "capture_kbuffer.frag", "prefix_sum.comp", "prefix_sum_add.comp", "resolve.comp",
        "depth_range.frag", "occupancy_fill.frag", "occupancy_count.comp", "shared_layout.h",
        "alloc_histogram.comp", "importance.comp", "importance_total.comp", "alloc_k.comp",
        "alloc_pack.comp"})
    EXPECT_FALSE(embeddedShader(name).empty()) << name;
}

TEST(GlContext, ReportsRendererAndExtensions) {
  MFR_REQUIRE_GL();
  const GlContext& c = sharedContext().value();
  std::cout << "  EGL platform: " << c.eglPlatform() << "\n  GL_RENDERER: " << c.renderer()
            << "\n  GL_VERSION: " << c.version() << "\n  extensions: " << c.extensionList().size()
            << "\n";
  const GlExtensions& e = c.extensions();
  std::cout << "  ARB_fragment_shader_interlock " << e.arbFragmentShaderInterlock
            << ", NV_fragment_shader_interlock " << e.nvFragmentShaderInterlock
            << ", INTEL_fragment_shader_ordering " << e.intelFragmentShaderOrdering
            << ", ARB_gpu_shader_int64 " << e.arbGpuShaderInt64 << ", NV_shader_atomic_int64 "
            << e.nvShaderAtomicInt64 << "\n";
  EXPECT_FALSE(c.renderer().empty());
  EXPECT_EQ(c.hasExtension("GL_ARB_gpu_shader_int64"), e.arbGpuShaderInt64);
}

TEST(GlEngine, UnsupportedMethodIsAnError) {
  MFR_REQUIRE_GL();
  auto scene = loadScene("procedural:layers");
  ASSERT_TRUE(scene.ok());
  auto engine = GlEngine::create(sharedContext().value(), *scene, *scene->defaultCamera, 32, 32,
                                 false, GlRaster::Exact);
  ASSERT_TRUE(engine.ok()) << engine.error().message;
  auto out = engine->render(methodPreset("dkb").value());
  ASSERT_FALSE(out.ok());
  EXPECT_NE(out.error().message.find("dkb"), std::string::npos) << out.error().message;
  // a variable-k method without its per-pixel allocation
  out = engine->render(methodPreset("kplus-sb").value());
  ASSERT_FALSE(out.ok());
  EXPECT_NE(out.error().message.find("kplus-sb"), std::string::npos) << out.error().message;
}

// Textured real scenes from ../shared/scenes at 128x128 (the scene's camera, else the bounds
// framed): n(p) identical per pixel, the captured node sets identical and the images within 1/255
// for the A-buffer, kplus-array (k 4) and kplus-heap with hybrid compositing (k 4). Skipped when
// the scenes folder is absent (a missing file in a present folder fails).
class GlVsCpuRealScene : public testing::TestWithParam<const char*> {};

TEST_P(GlVsCpuRealScene, CountsNodesAndImagesEqualTheCpuEngine) {
  MFR_REQUIRE_GL();
  MFR_SHARED_SCENE(path, GetParam());
  auto loaded = loadScene(path.string());
  ASSERT_TRUE(loaded.ok()) << loaded.error().message;
  const Scene& scene = *loaded;
  ASSERT_FALSE(scene.textures.empty()) << "a textured scene";
  const Camera camera =
      scene.defaultCamera ? *scene.defaultCamera : frameBounds(sceneBounds(scene));
  const int size = 128;
  auto frame = RasterFrame::build(scene, camera, RasterOptions{size, size, 16, 0});
  ASSERT_TRUE(frame.ok()) << frame.error().message;
  auto engine =
      GlEngine::create(sharedContext().value(), scene, camera, size, size, false, GlRaster::Exact);
  ASSERT_TRUE(engine.ok()) << engine.error().message;
  const std::vector<uint32_t> counts = countFragments(*frame);
  size_t covered = 0, differ = 0;
  uint64_t fragments = 0;
  uint32_t maxN = 0;
  bool countsChecked = false;
  for (const char* preset : {"abuffer", "kplus-array", "kplus-heap"}) {
    MethodDesc method = methodPreset(preset).value();
    if (std::string(preset) != "abuffer") method.k = 4;
    if (std::string(preset) == "kplus-heap") method.compositing = Compositing::Hybrid;
    RenderOptions co;
    co.keepStores = true;
    co.background = kBackground;
    auto cpu = render(*frame, method, co);
    ASSERT_TRUE(cpu.ok()) << cpu.error().message;
    GlRenderOptions go;
    go.background = kBackground;
    go.readNodes = true;
    go.warmUp = false;
    auto gl = engine->render(method, go);
    ASSERT_TRUE(gl.ok()) << gl.error().message;
    if (!countsChecked) {
      ASSERT_EQ(gl->counts.size(), counts.size());
      for (size_t p = 0; p < counts.size(); ++p) {
        covered += counts[p] > 0 || gl->counts[p] > 0;
        fragments += counts[p];
        maxN = std::max(maxN, counts[p]);
        if (counts[p] != gl->counts[p]) {
          if (differ < 20)
            std::cout << "  pixel (" << p % size << ", " << p / size << "): CPU n " << counts[p]
                      << ", GL n " << gl->counts[p] << "\n";
          ++differ;
        }
      }
      std::cout << "  " << GetParam() << ": n(p) " << fragments << " fragments, " << covered
                << " covered pixels, max " << maxN << ", " << differ << " differ\n";
      EXPECT_GT(fragments, 0u);
      EXPECT_EQ(differ, 0u);
      EXPECT_EQ(gl->fragments, fragments);
      countsChecked = true;
    }
    std::cout << "  " << preset << (method.compositing == Compositing::Hybrid ? " hybrid" : "")
              << ":\n";
    compareNodes(*cpu, *gl, size);
    compareImages(cpu->image, gl->image);
  }
}

INSTANTIATE_TEST_SUITE_P(
    Khronos, GlVsCpuRealScene,
    testing::Values("khronos/IridescentDishWithOlives/glTF/IridescentDishWithOlives.gltf",
                    "khronos/AlphaBlendModeTest/glTF-Binary/AlphaBlendModeTest.glb"),
    [](const testing::TestParamInfo<const char*>& info) {
      return std::string(info.index == 0 ? "IridescentDishWithOlives" : "AlphaBlendModeTest");
    });

// --gl-sync interlock: the k-buffer capture's interlock variant compiles and links (and captures
// what the lock variant captures) where the driver offers an interlock extension; without one,
// GlEngine::create names the extensions it lacks in one line, and the test skips.
TEST(GlEngine, InterlockVariantCompiles) {
  MFR_REQUIRE_GL();
  auto scene = loadScene("procedural:layers");
  ASSERT_TRUE(scene.ok());
  const std::string ext = interlockExtension(sharedContext().value());
  auto engine = GlEngine::create(sharedContext().value(), *scene, *scene->defaultCamera, 32, 32,
                                 true, GlRaster::Exact);
  if (ext.empty()) {
    ASSERT_FALSE(engine.ok());
    const std::string m = engine.error().message;
    EXPECT_EQ(m.find("--gl-sync interlock: the driver offers none of "
                     "GL_ARB_fragment_shader_interlock"),
              0u)
        << m;
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    GTEST_SKIP() << "the driver (" << sharedContext()->renderer()
                 << ") offers no fragment shader interlock: the interlock variant is not compiled";
  }
  ASSERT_TRUE(engine.ok()) << engine.error().message;
  auto lock = GlEngine::create(sharedContext().value(), *scene, *scene->defaultCamera, 32, 32,
                               false, GlRaster::Exact);
  ASSERT_TRUE(lock.ok()) << lock.error().message;
  for (const char* preset : {"kplus-array", "kplus-heap"}) {
    GlRenderOptions o;
    o.readNodes = true;
    auto a = engine->render(methodPreset(preset).value(), o);
    auto b = lock->render(methodPreset(preset).value(), o);
    ASSERT_TRUE(a.ok() && b.ok());
    EXPECT_EQ(a->nodeCounts, b->nodeCounts) << preset;
    EXPECT_EQ(a->image.pixels, b->image.pixels) << preset;
  }
}

// Pass times at 128x128 and 512x512 (printed; not a pass/fail criterion; about a minute on
// llvmpipe, so disabled: run with --gtest_also_run_disabled_tests --gtest_filter=*PassTimes).
TEST(GlEngine, DISABLED_PassTimes) {
  MFR_REQUIRE_GL();
  for (const char* name : {"procedural:layers", "procedural:hairball"}) {
    auto scene = loadScene(name);
    ASSERT_TRUE(scene.ok());
    for (int size : {128, 512}) {
      auto engine = GlEngine::create(sharedContext().value(), *scene, *scene->defaultCamera, size,
                                     size, false, GlRaster::Exact);
      ASSERT_TRUE(engine.ok()) << engine.error().message;
      for (const char* preset : {"abuffer", "kplus-array"}) {
        MethodDesc method = methodPreset(preset).value();
        if (std::string(preset) != "abuffer") method.k = 4;
        auto out = engine->render(method);
        ASSERT_TRUE(out.ok()) << out.error().message;
        std::cout << "  " << name << " " << size << "x" << size << " " << preset << " ("
                  << out->fragments << " fragments):";
        for (const GlPassTime& t : out->passes)
          std::cout << " " << t.name << " " << t.gpuMs << " ms (wall " << t.wallMs << ")";
        std::cout << "\n";
      }
    }
  }
}

}  // namespace
}  // namespace mfr::gl
