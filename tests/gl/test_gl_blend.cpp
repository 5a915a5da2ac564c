// Blend modes on the GL engine (shaders/raster_common.glsl packBlended, method_math.h blendStep in
// resolve.comp, resolve_list.comp, peel_step.comp, the tails, aoit_color.frag): with the CPU
// engine's raster (--gl-raster exact) the GL engine's node words are the CPU engine's, so for every
// method that takes a mode the two engines' images agree within float rounding on procedural
// scenes of each mode; a method refusing a mode refuses it on GL with the CPU engine's message.
// Without a GL 4.5 context the tests skip (fail under CI=true).
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "../test_util.hpp"
#include "gl_engine_or_skip.hpp"
#include "mfr/cpu/cpu_engine.hpp"
#include "mfr/method/blend_support.hpp"
#include "mfr/method/make_method.hpp"
#include "mfr/scene/load.hpp"

namespace mfr::gl {
namespace {

const glm::vec3 kBg(0.2f, 0.4f, 0.6f);

TEST(GlBlend, SameImagesAsTheCpuEngine) {
  MFR_GL_ENGINE_OR_SKIP(gl, "auto", "exact");
  CpuEngine cpu(EngineOptions{2, 16});
  struct Preset {
    const char* name;
    const char* composite;
  };
  const Preset presets[] = {{"abuffer", nullptr},   {"kplus-sb", "kbuffer"},
                            {"kplus-sb", "hybrid"}, {"linked-list", "kbuffer"},
                            {"peel", nullptr},      {"dual-peel", nullptr},
                            {"aoit8", nullptr},     {"wboit", nullptr}};
  int compared = 0;
  for (const char* mode : {"premultiplied", "additive", "multiply"}) {
    // (8 fragments per pixel on the layers: AOIT's 8 nodes keep them all, so its image does not
    // depend on the arrival order, which GL does not fix; the particles pile up more: no aoit8)
    for (const char* base :
         {"procedural:particles?count=150&clouds=3", "procedural:layers?k=4&r=2"}) {
      const std::string source = std::string(base) + "&blend=" + mode;
      const Scene scene = loadScene(source).value();
      const View view{&scene, *scene.defaultCamera, 64, 48};
      for (const Preset& p : presets) {
        MethodOverrides o;
        if (p.composite) o.composite = p.composite;
        const MethodDesc method = makeMethod(p.name, o).value();
        RenderOptions options;
        options.background = kBg;
        options.budgetBytes = 4u << 20;
        RenderOptions cpuOptions = options;
        cpuOptions.capture = CaptureMode::FragmentParallel;
        auto g = gl->render(view, method, options);
        auto r = cpu.render(view, method, cpuOptions);
        const std::string what = source + " " + p.name + (p.composite ? p.composite : "");
        if (std::string(p.name) == "aoit8" && source.find("particles") != std::string::npos)
          continue;
        if ((blendModesOf(method) & scene.blendModes()) != scene.blendModes()) {
          ASSERT_FALSE(g.ok()) << what;
          ASSERT_FALSE(r.ok()) << what;
          EXPECT_EQ(g.error().message, r.error().message);
          continue;
        }
        ASSERT_TRUE(g.ok()) << what << ": " << g.error().message;
        ASSERT_TRUE(r.ok()) << what << ": " << r.error().message;
        EXPECT_EQ(g->stats.captured, r->stats.captured) << what;
        // float rounding; the hybrid tails and AOIT's colour sums add in arrival order
        const bool orderDependent = (p.composite && std::string(p.composite) == "hybrid") ||
                                    std::string(p.name) == "aoit8" ||
                                    std::string(p.name) == "wboit";
        EXPECT_LT(::mfr::test::largestDifference(g->image, r->image),
                  orderDependent ? 2e-5f : 2e-6f)
            << what;
        ++compared;
      }
    }
  }
  EXPECT_GE(compared, 30);
}

}  // namespace
}  // namespace mfr::gl
