// The exact A-buffer (ground truth): compositing against an independent reference, order
// independence, memory accounting, determinism, analytic depth complexity.
#include <gtest/gtest.h>

#include <cmath>

#include "mfr/cpu/render.hpp"
#include "mfr/scene/load.hpp"
#include "mfr/scene/procedural_geometry.hpp"
#include "test_util.hpp"

namespace mfr {
namespace {

RenderOutput renderWith(const Scene& scene, const Camera& camera, int size,
                        const std::string& preset, RenderOptions options = {}, int threads = 2) {
  RasterOptions ro;
  ro.width = size;
  ro.height = size;
  ro.threads = threads;
  auto frame = RasterFrame::build(scene, camera, ro);
  EXPECT_TRUE(frame.ok());
  auto out = render(frame.value(), methodPreset(preset).value(), options);
  EXPECT_TRUE(out.ok()) << (out.ok() ? "" : out.error().message);
  return std::move(out.value());
}

// Independent reference: sRGB by its formula (not the lookup tables), compositing in double.
double srgbDecode(double c) {
  return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}
double srgbEncode(double l) {
  l = std::clamp(l, 0.0, 1.0);
  return l <= 0.0031308 ? l * 12.92 : 1.055 * std::pow(l, 1.0 / 2.4) - 0.055;
}

TEST(ABuffer, CompositesLikeAnIndependentFrontToBackReference) {
  const int size = 16;
  // three full-screen layers submitted in the order middle, far, near
  struct Layer {
    float z;
    glm::vec4 color;
  };
  const Layer layers[3] = {{-1.0f, {0.1f, 0.9f, 0.2f, 0.25f}},
                           {-2.0f, {0.2f, 0.3f, 1.0f, 0.75f}},
                           {-0.5f, {1.0f, 0.2f, 0.1f, 0.5f}}};
  std::vector<test::TestTriangle> tris;
  for (const Layer& l : layers) {
    auto rect = test::screenRect(-2, -2, size + 2, size + 2, size, l.z, l.color);
    tris.insert(tris.end(), rect.begin(), rect.end());
  }
  Scene scene = test::makeScene(tris);
  const glm::dvec3 background(0.9, 0.95, 1.0);
  RenderOptions options;
  options.background = background;
  const RenderOutput out = renderWith(scene, test::screenCamera(), size, "abuffer", options);
  const Camera cam = test::screenCamera();
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const Ray r = pixelRay(cam, size, size, x, y);
      const double cosine = std::fabs(r.direction.z);  // normals are +z
      const double light = 0.2 + 0.8 * cosine;
      glm::dvec3 color(0.0);
      double T = 1.0;
      for (int i : {2, 0, 1}) {  // near to far
        const glm::dvec4 c(layers[i].color);
        // the fragment colour travels as sRGB8 + alpha8
        const glm::dvec3 shaded(srgbDecode(std::round(srgbEncode(c.r * light) * 255.0) / 255.0),
                                srgbDecode(std::round(srgbEncode(c.g * light) * 255.0) / 255.0),
                                srgbDecode(std::round(srgbEncode(c.b * light) * 255.0) / 255.0));
        const double a = std::round(c.a * 255.0) / 255.0;
        color += T * a * shaded;
        T *= 1.0 - a;
      }
      color += T * background;
      const glm::vec3 got = out.image.at(x, y);
      for (int ch = 0; ch < 3; ++ch)
        EXPECT_NEAR(got[ch], color[ch], 2e-3) << "pixel " << x << "," << y << " channel " << ch;
    }
  EXPECT_EQ(out.stats.maxDepthComplexity.value(), 3u);
}

TEST(ABuffer, EqualDepthsGiveTheSameImageInAnySubmissionOrder) {
  const int size = 8;
  const glm::vec4 red(1, 0, 0, 0.5f), blue(0, 0, 1, 0.5f);
  auto a = test::screenRect(-1, -1, size + 1, size + 1, size, -1.0f, red);
  auto b = test::screenRect(-1, -1, size + 1, size + 1, size, -1.0f, blue);
  std::vector<test::TestTriangle> ab = a, ba = b;
  ab.insert(ab.end(), b.begin(), b.end());
  ba.insert(ba.end(), a.begin(), a.end());
  const RenderOutput first = renderWith(test::makeScene(ab), test::screenCamera(), size, "abuffer");
  const RenderOutput second =
      renderWith(test::makeScene(ba), test::screenCamera(), size, "abuffer");
  EXPECT_EQ(encodeSrgb(first.image).rgba, encodeSrgb(second.image).rgba);
}

TEST(ABuffer, ReportsExactBytesAndFragments) {
  const int size = 32;
  const Scene scene = test::makeScene(test::screenRect(4, 4, 20, 12, size));
  const RenderOutput out = renderWith(scene, test::screenCamera(), size, "abuffer");
  const uint64_t fragments = 16 * 8;
  EXPECT_EQ(out.stats.fragmentsGenerated, fragments);
  EXPECT_EQ(out.stats.captured, fragments);
  EXPECT_EQ(out.stats.lost, 0u);
  // 4 B counter + 4 B offset per pixel, 8 B per fragment node
  EXPECT_EQ(out.stats.bytesUsed, size * size * 8u + fragments * 8u);
  EXPECT_EQ(out.stats.coveredPixels, fragments);
  EXPECT_DOUBLE_EQ(out.stats.meanDepthComplexity.value(), 1.0);
}

TEST(ABuffer, BudgetBelowItsNeedIsAnErrorNamingTheBudget) {
  const int size = 32;
  const Scene scene = test::makeScene(test::screenRect(4, 4, 20, 12, size));
  RasterOptions ro{size, size, 32, 1};
  auto frame = RasterFrame::build(scene, test::screenCamera(), ro);
  RenderOptions options;
  options.budgetBytes = 1000;
  auto out = render(frame.value(), methodPreset("abuffer").value(), options);
  ASSERT_FALSE(out.ok());
  EXPECT_NE(out.error().message.find("1000 B"), std::string::npos) << out.error().message;
}

TEST(ABuffer, SameImageBytesForOneAndManyThreads) {
  auto scene = loadScene("procedural:hairball?strands=400");
  ASSERT_TRUE(scene.ok());
  const Camera cam = *scene->defaultCamera;
  RenderOptions options;
  options.keepStores = true;
  const RenderOutput one = renderWith(*scene, cam, 160, "abuffer", options, 1);
  const RenderOutput many = renderWith(*scene, cam, 160, "abuffer", options, 2);
  EXPECT_GT(one.stats.fragmentsGenerated, 10000u);
  EXPECT_EQ(encodeSrgb(one.image).rgba, encodeSrgb(many.image).rgba);
  EXPECT_EQ(one.nodes, many.nodes);
  EXPECT_EQ(one.depthComplexity, many.depthComplexity);
}

TEST(ABuffer, SpheresDepthComplexityEqualsTheAnalyticCount) {
  auto scene = loadScene("procedural:spheres");
  ASSERT_TRUE(scene.ok());
  const int size = 200;
  const RenderOutput out = renderWith(*scene, *scene->defaultCamera, size, "abuffer");
  // the frame's camera has the fitted clip planes; the analytic count uses the same camera
  RasterOptions ro{size, size, 32, 2};
  const Camera cam = RasterFrame::build(*scene, *scene->defaultCamera, ro)->camera();
  const float tolerance = sphereTessellationError(kSpheresDefaultScale, kSpheresDefaultDetail);
  int checked = 0;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      float margin = 0.0f;
      const int expected = sphereLayersAnalytic(cam, size, size, x, y, kSpheresDefaultCount,
                                                kSpheresDefaultScale, &margin);
      if (margin <= tolerance * 1.5f) continue;  // silhouettes of the tessellated spheres
      ASSERT_EQ(static_cast<int>(out.depthComplexity[y * size + x]), expected) << x << "," << y;
      ++checked;
    }
  EXPECT_GT(checked, size * size / 2);
  EXPECT_EQ(out.stats.maxDepthComplexity.value(), 2u * kSpheresDefaultCount);
}

}  // namespace
}  // namespace mfr
