// Per-pixel linked lists (`linked-list`, Yang et al. EGSR 2010) on the GL engine: without a budget
// the image is the GL A-buffer's and every fragment is captured; with an overflowing pool the GL
// atomic counter admits fragments in its own arrival order, so only the counts are compared with
// the CPU engine (captured = the pool's nodes, lost = the rest, bytes the model's), and the read
// back lists hold exactly the pool's nodes, each sorted (the resolve sorts in place). The GL
// images against the CPU engine's where the pool holds everything: GlSeam (test_gl_seam.cpp).
// Without a GL 4.5 context the tests skip (fail under CI=true).
#include <gtest/gtest.h>

#include <algorithm>

#include "gl_engine_or_skip.hpp"
#include "mfr/cpu/cpu_engine.hpp"
#include "mfr/scene/load.hpp"

namespace mfr::gl {
namespace {

TEST(GlLinkedList, UnboundedIsTheABuffer) {
  MFR_GL_ENGINE_OR_SKIP(gl, "auto", "exact");
  const Scene scene = loadScene("procedural:hairball?strands=150").value();
  const View view{&scene, *scene.defaultCamera, 64, 48};
  RenderOptions options;
  options.background = glm::vec3(0.2f, 0.4f, 0.6f);
  options.keepStores = true;
  auto ab = gl->render(view, methodPreset("abuffer").value(), options);
  auto ll = gl->render(view, methodPreset("linked-list").value(), options);
  ASSERT_TRUE(ab.ok()) << ab.error().message;
  ASSERT_TRUE(ll.ok()) << ll.error().message;
  EXPECT_EQ(ll->image.pixels, ab->image.pixels);
  EXPECT_EQ(ll->stats.captured, ab->stats.fragmentsGenerated);
  EXPECT_EQ(ll->stats.lost, 0u);
  EXPECT_EQ(ll->stats.fragmentSlots, ab->stats.fragmentsGenerated);
  EXPECT_EQ(ll->kMap, ab->depthComplexity);
  // the lists read back: each pixel's nodes, sorted by the resolve, as the A-buffer's
  for (size_t p = 0; p < ll->counts.size(); ++p) {
    ASSERT_EQ(ll->counts[p], ab->counts[p]) << p;
    EXPECT_TRUE(
        std::equal(ll->nodes.begin() + static_cast<std::ptrdiff_t>(ll->offsets[p]),
                   ll->nodes.begin() + static_cast<std::ptrdiff_t>(ll->offsets[p] + ll->counts[p]),
                   ab->nodes.begin() + static_cast<std::ptrdiff_t>(ab->offsets[p])))
        << p;
  }
}

TEST(GlLinkedList, OverflowCountsEqualTheCpuEngines) {
  MFR_GL_ENGINE_OR_SKIP(gl, "auto", "exact");
  const Scene scene = loadScene("procedural:hairball?strands=150").value();
  const View view{&scene, *scene.defaultCamera, 64, 48};
  CpuEngine cpu(EngineOptions{2, 16});
  for (Compositing rule : {Compositing::KBuffer, Compositing::Hybrid}) {
    MethodDesc m = methodPreset("linked-list").value();
    m.compositing = rule;
    const uint64_t pixels = 64 * 48;
    const uint64_t pool = 3000;
    RenderOptions options;
    options.budgetBytes = pixels * (rule == Compositing::Hybrid ? 24 : 4) + 4 + 12 * pool;
    options.keepStores = true;
    auto g = gl->render(view, m, options);
    auto c = cpu.render(view, m, options);
    ASSERT_TRUE(g.ok()) << g.error().message;
    ASSERT_TRUE(c.ok()) << c.error().message;
    ASSERT_GT(c->stats.fragmentsGenerated, pool);
    EXPECT_EQ(g->stats.fragmentsGenerated, c->stats.fragmentsGenerated);
    EXPECT_EQ(g->stats.captured, pool);
    EXPECT_EQ(c->stats.captured, pool);
    EXPECT_EQ(g->stats.lost, c->stats.fragmentsGenerated - pool);
    EXPECT_EQ(g->stats.bytesUsed, *options.budgetBytes);
    EXPECT_EQ(g->stats.bytesByCategory, c->stats.bytesByCategory);
    EXPECT_EQ(g->nodes.size(), pool);
    uint64_t held = 0;
    for (size_t p = 0; p < g->counts.size(); ++p) {
      held += g->counts[p];
      EXPECT_EQ(g->kMap[p], g->counts[p]);
      EXPECT_TRUE(std::is_sorted(
          g->nodes.begin() + static_cast<std::ptrdiff_t>(g->offsets[p]),
          g->nodes.begin() + static_cast<std::ptrdiff_t>(g->offsets[p] + g->counts[p])));
    }
    EXPECT_EQ(held, pool);
  }
}

}  // namespace
}  // namespace mfr::gl
