// Rasterizer rules: fill rule, coverage of tiny triangles, clipping, perspective-correct
// interpolation, determinism.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "mfr/core/color.hpp"
#include "mfr/cpu/raster_frame.hpp"
#include "test_util.hpp"

namespace mfr {
namespace {

using test::makeScene;
using test::screenCamera;
using test::screenPoint;
using test::TestTriangle;

RasterFrame buildFrame(const Scene& scene, int size, const Camera& camera = screenCamera(),
                       int threads = 2) {
  RasterOptions o;
  o.width = size;
  o.height = size;
  o.threads = threads;
  auto frame = RasterFrame::build(scene, camera, o);
  EXPECT_TRUE(frame.ok()) << (frame.ok() ? "" : frame.error().message);
  return std::move(frame.value());
}

std::vector<Fragment> allFragments(const RasterFrame& frame) {
  std::vector<std::vector<Fragment>> perTile(frame.tileCount());
  frame.forEachTile([&](int tile) {
    frame.rasterizeTile<ShadeMode::Full>(
        tile, EmitAll{[&](const Fragment& f) { perTile[tile].push_back(f); }});
  });
  std::vector<Fragment> all;
  for (const auto& t : perTile) all.insert(all.end(), t.begin(), t.end());
  return all;
}

std::vector<int> coverage(const RasterFrame& frame) {
  std::vector<int> count(frame.pixelCount(), 0);
  for (const Fragment& f : allFragments(frame)) ++count[f.pixel];
  return count;
}

TEST(Rasterizer, JitteredMeshCoversEveryPixelExactlyOnce) {
  // a triangulated grid reaching past the viewport, vertices jittered to arbitrary sub-pixel
  // positions: every shared edge must give each pixel centre to exactly one triangle
  const int size = 64, cells = 12;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> jitter(-2.0, 2.0);
  std::vector<std::vector<glm::vec3>> grid(cells + 1, std::vector<glm::vec3>(cells + 1));
  for (int j = 0; j <= cells; ++j)
    for (int i = 0; i <= cells; ++i) {
      const double step = (size + 16.0) / cells;
      const bool border = i == 0 || j == 0 || i == cells || j == cells;
      grid[j][i] = screenPoint(-8.0 + i * step + (border ? 0.0 : jitter(rng)),
                               -8.0 + j * step + (border ? 0.0 : jitter(rng)), size);
    }
  std::vector<TestTriangle> tris;
  for (int j = 0; j < cells; ++j)
    for (int i = 0; i < cells; ++i) {
      tris.push_back({grid[j][i], grid[j][i + 1], grid[j + 1][i + 1]});
      tris.push_back({grid[j][i], grid[j + 1][i + 1], grid[j + 1][i]});
    }
  const std::vector<int> c = coverage(buildFrame(makeScene(tris), size));
  for (int p = 0; p < size * size; ++p)
    ASSERT_EQ(c[p], 1) << "pixel " << p % size << "," << p / size;
}

TEST(Rasterizer, FanAroundAPixelCentreCoversItOnce) {
  const int size = 16;
  const glm::vec3 centre = screenPoint(8.5, 8.5, size);  // exactly a pixel centre
  std::vector<TestTriangle> tris;
  const int spokes = 8;
  for (int i = 0; i < spokes; ++i) {
    const double a0 = 2.0 * M_PI * i / spokes, a1 = 2.0 * M_PI * (i + 1) / spokes;
    tris.push_back({centre, screenPoint(8.5 + 20 * std::cos(a0), 8.5 + 20 * std::sin(a0), size),
                    screenPoint(8.5 + 20 * std::cos(a1), 8.5 + 20 * std::sin(a1), size)});
  }
  const std::vector<int> c = coverage(buildFrame(makeScene(tris), size));
  for (int p = 0; p < size * size; ++p)
    ASSERT_EQ(c[p], 1) << "pixel " << p % size << "," << p / size;
}

TEST(Rasterizer, TopLeftRuleOnEdgesThroughPixelCentres) {
  // rectangle with all four edges through pixel centres: the left and top edges are inside,
  // the right and bottom edges outside
  const int size = 16;
  const std::vector<int> c =
      coverage(buildFrame(makeScene(test::screenRect(2.5, 3.5, 6.5, 9.5, size)), size));
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const bool inside = x >= 2 && x <= 5 && y >= 3 && y <= 8;
      EXPECT_EQ(c[y * size + x], inside ? 1 : 0) << x << "," << y;
    }
}

TEST(Rasterizer, PixelSizedTriangleCoversItsCentreOnly) {
  const int size = 16;
  // a right triangle whose hypotenuse passes just beyond the centre of pixel (5, 7)
  const std::vector<TestTriangle> tris = {
      {screenPoint(5.0, 7.0, size), screenPoint(6.2, 7.0, size), screenPoint(5.0, 8.2, size)}};
  const std::vector<int> c = coverage(buildFrame(makeScene(tris), size));
  int total = 0;
  for (int v : c) total += v;
  EXPECT_EQ(total, 1);
  EXPECT_EQ(c[7 * size + 5], 1);
}

TEST(Rasterizer, SubPixelTriangleMissingEveryCentreMakesNoFragment) {
  const int size = 16;
  const std::vector<TestTriangle> tris = {
      {screenPoint(5.1, 7.1, size), screenPoint(5.4, 7.1, size), screenPoint(5.1, 7.4, size)}};
  const std::vector<int> c = coverage(buildFrame(makeScene(tris), size));
  for (int v : c) EXPECT_EQ(v, 0);
}

TEST(Rasterizer, SubPixelTriangleOverACentreMakesOneFragment) {
  const int size = 16;
  const std::vector<TestTriangle> tris = {
      {screenPoint(5.3, 7.3, size), screenPoint(5.8, 7.4, size), screenPoint(5.4, 7.8, size)}};
  const std::vector<int> c = coverage(buildFrame(makeScene(tris), size));
  int total = 0;
  for (int v : c) total += v;
  EXPECT_EQ(total, 1);
  EXPECT_EQ(c[7 * size + 5], 1);
}

// Brute-force reference: does the ray through the pixel centre hit the triangle in front of the
// near plane (distance along the view axis > near)?
bool rayHits(const Camera& cam, int size, int x, int y, const TestTriangle& t, float zNear) {
  const Ray r = pixelRay(cam, size, size, x, y);
  const glm::dvec3 o(r.origin), d(r.direction), a(t.a), b(t.b), c(t.c);
  const glm::dvec3 e1 = b - a, e2 = c - a, p = glm::cross(d, e2);
  const double det = glm::dot(e1, p);
  if (std::fabs(det) < 1e-12) return false;
  const glm::dvec3 s = o - a;
  const double u = glm::dot(s, p) / det;
  const glm::dvec3 q = glm::cross(s, e1);
  const double v = glm::dot(d, q) / det;
  const double dist = glm::dot(e2, q) / det;
  const glm::dvec3 forward = glm::normalize(glm::dvec3(cam.target - cam.eye));
  return u >= 0 && v >= 0 && u + v <= 1 && dist * glm::dot(d, forward) > zNear;
}

TEST(Rasterizer, TriangleCrossingTheNearPlaneIsClippedNotInverted) {
  const int size = 64;
  Camera cam = screenCamera();
  // one vertex behind the eye (z = 3 > eye z = 1), two in front
  const TestTriangle tri{{-0.5f, -0.6f, 3.0f}, {0.8f, -0.4f, -2.0f}, {-0.3f, 0.7f, -1.0f}};
  const RasterFrame frame = buildFrame(makeScene({tri}), size, cam);
  const std::vector<Fragment> frags = allFragments(frame);
  ASSERT_FALSE(frags.empty());
  std::vector<int> c(size * size, 0);
  for (const Fragment& f : frags) {
    EXPECT_GE(f.depth, 0.0f);
    EXPECT_LE(f.depth, 1.0f);
    ++c[f.pixel];
  }
  int mismatches = 0, covered = 0;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const bool expected = rayHits(cam, size, x, y, tri, frame.camera().zNear);
      covered += expected;
      ASSERT_LE(c[y * size + x], 1);
      mismatches += (c[y * size + x] == 1) != expected;
    }
  ASSERT_GT(covered, 100);
  // only pixel centres within rounding distance of an edge may disagree
  EXPECT_LE(mismatches, covered / 100 + 2);
}

TEST(Rasterizer, TriangleBehindTheCameraMakesNoFragment) {
  const TestTriangle tri{{-0.5f, -0.5f, 2.0f}, {0.5f, -0.5f, 2.0f}, {0.0f, 0.5f, 2.5f}};
  const std::vector<int> c = coverage(buildFrame(makeScene({tri}), 32));
  for (int v : c) EXPECT_EQ(v, 0);
}

TEST(Rasterizer, DepthAndTextureCoordinatesArePerspectiveCorrect) {
  // a quad strongly tilted away from the camera, textured with a horizontal gradient in u: the
  // red channel of each fragment must follow the u of the ray's hit point, not an affine blend
  const int size = 64;
  Scene scene;
  scene.name = "tilted";
  scene.positions = {
      {-1.0f, -0.8f, 0.5f}, {1.0f, -0.8f, 0.5f}, {1.0f, 0.8f, -6.0f}, {-1.0f, 0.8f, -6.0f}};
  const glm::vec3 n = glm::normalize(
      glm::cross(scene.positions[1] - scene.positions[0], scene.positions[3] - scene.positions[0]));
  scene.normals.assign(4, n);
  scene.uvs = {{0.0f, 1.0f}, {1.0f, 1.0f}, {1.0f, 0.0f}, {0.0f, 0.0f}};
  scene.indices = {0, 1, 2, 0, 2, 3};
  scene.triangleMaterial = {0, 0};
  Texture tex;  // 256 x 1, red = v along the quad's depth direction (texture rows: v)
  tex.width = 1;
  tex.height = 256;
  for (int i = 0; i < 256; ++i) tex.rgba.insert(tex.rgba.end(), {uint8_t(i), 0, 0, 255});
  scene.textures.push_back(tex);
  Material m;
  m.baseColorTexture = 0;
  m.alphaMode = AlphaMode::Blend;
  scene.materials.push_back(m);
  Camera cam = screenCamera();
  cam.eye = {0.0f, 0.3f, 2.0f};
  cam.target = {0.0f, 0.0f, -2.0f};
  cam.zNear = 0.5f;
  cam.zFar = 20.0f;
  const RasterFrame frame = buildFrame(scene, size, cam);
  const glm::mat4 viewProj =
      projectionMatrix(frame.camera(), size, size) * viewMatrix(frame.camera());
  int checked = 0;
  for (const Fragment& f : allFragments(frame)) {
    const int x = static_cast<int>(f.pixel % size), y = static_cast<int>(f.pixel / size);
    const Ray r = pixelRay(frame.camera(), size, size, x, y);
    const float t = glm::dot(scene.positions[0] - r.origin, n) / glm::dot(r.direction, n);
    const glm::vec3 hit = r.origin + t * r.direction;
    // window depth of the hit point
    const glm::vec4 clip = viewProj * glm::vec4(hit, 1.0f);
    EXPECT_NEAR(f.depth, clip.z / clip.w * 0.5f + 0.5f, 2e-5f);
    // v of the hit point (bilinear param along the quad's y extent)
    const float v = (0.8f - hit.y) / 1.6f;
    const float cosine = std::fabs(glm::dot(n, -r.direction));
    EXPECT_NEAR(std::fabs(f.ndotv), cosine, 1e-3f);
    // the texel values are sRGB codes i/255 sampled bilinearly at v*256-0.5 (clamped at the
    // ends by the repeat wrap only near v = 0 or 1)
    if (v < 0.02f || v > 0.98f) continue;
    const float code = v * 256.0f - 0.5f;
    const float expectedLinear = srgbToLinear(code / 255.0f) * (kAmbient + (1 - kAmbient) * cosine);
    const float got = decodeSrgb8(static_cast<uint8_t>(f.rgba & 0xff));
    EXPECT_NEAR(got, expectedLinear, 0.01f + 0.03f * expectedLinear) << x << "," << y;
    ++checked;
  }
  EXPECT_GT(checked, 500);
}

TEST(Rasterizer, SameFragmentsForAnyThreadCount) {
  const int size = 48;
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-1.2f, 1.2f), z(-3.0f, 0.5f);
  std::vector<TestTriangle> tris;
  for (int i = 0; i < 300; ++i)
    tris.push_back({{u(rng), u(rng), z(rng)},
                    {u(rng), u(rng), z(rng)},
                    {u(rng), u(rng), z(rng)},
                    {0.3f, 0.6f, 0.9f, 0.4f}});
  const Scene scene = makeScene(tris);
  auto collect = [&](int threads) {
    const RasterFrame frame = buildFrame(scene, size, screenCamera(), threads);
    std::vector<std::vector<Fragment>> perPixel(frame.pixelCount());
    for (const Fragment& f : allFragments(frame)) perPixel[f.pixel].push_back(f);
    return perPixel;
  };
  const auto one = collect(1), many = collect(2);
  size_t total = 0;
  for (size_t p = 0; p < one.size(); ++p) {
    ASSERT_EQ(one[p].size(), many[p].size());
    total += one[p].size();
    for (size_t i = 0; i < one[p].size(); ++i) {
      EXPECT_EQ(one[p][i].prim, many[p][i].prim);
      EXPECT_EQ(one[p][i].depth, many[p][i].depth);
      EXPECT_EQ(one[p][i].rgba, many[p][i].rgba);
      if (i > 0) {
        EXPECT_LT(one[p][i - 1].prim, one[p][i].prim) << "primitive order within a pixel";
      }
    }
  }
  EXPECT_GT(total, 1000u);
}

TEST(Rasterizer, RejectsAbsurdSizes) {
  const Scene scene = makeScene(test::screenRect(0, 0, 8, 8, 8));
  for (auto [w, h] : {std::pair{0, 10}, {10, -1}, {16385, 10}, {10, 100000}}) {
    RasterOptions o;
    o.width = w;
    o.height = h;
    auto frame = RasterFrame::build(scene, screenCamera(), o);
    ASSERT_FALSE(frame.ok());
    EXPECT_NE(frame.error().message.find(std::to_string(w) + "x" + std::to_string(h)),
              std::string::npos);
  }
}

}  // namespace
}  // namespace mfr
