// glTF alpha modes rendered, not only loaded: OPAQUE hides what is behind it, MASK drops the
// fragments below alphaCutoff and keeps the others as opaque, and `--alpha a`
// (Scene::alphaOverride) gives every material alpha a. Tiny glTF files with two overlapping
// camera-facing quads of known colour are written at test time and rendered with the exact
// A-buffer; every pixel is checked against an independent front-to-back reference
// (tests/reference_shading.hpp).
//
// Layout (camera at (0, 0, 2) looking at the origin, fov 90, 32 x 32 pixels):
//   far quad B  [-1, 1] x [-1, 1] at z = 0     BLEND (0.1, 0.2, 0.9, 0.5)  pixels 8..23 x 8..23
//   near quad A [0, 1.5] x [-1.5, 1.5] at z = 0.5, the material under test:  pixels 16..31 x 0..31
// so the image has four regions: nothing, B alone, A over B, A alone. A is listed first in the
// file: primitive order is not depth order.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include "cli_runner.hpp"
#include "gltf_quads.hpp"
#include "mfr/core/image.hpp"
#include "mfr/cpu/render.hpp"
#include "mfr/scene/load.hpp"
#include "reference_shading.hpp"

namespace mfr {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr int kSize = 32;
constexpr double kFov = 90.0;
const glm::dvec3 kNearColor(0.8, 0.1, 0.1), kFarColor(0.1, 0.2, 0.9);
constexpr double kFarAlpha = 0.5;
const glm::dvec3 kBackground(0.3, 0.6, 0.2);

fs::path tempDir() {
  static const fs::path dir = test::processTempDir("mfr_alpha_modes_test");
  return dir;
}

std::string writeScene(const std::string& name, const json& nearMaterial) {
  const json farMaterial =
      test::gltfMaterial({kFarColor.r, kFarColor.g, kFarColor.b, kFarAlpha}, "BLEND");
  const std::string text = test::gltfWithQuads({{0.0f, -1.5f, 1.5f, 1.5f, 0.5f, nearMaterial},
                                                {-1.0f, -1.0f, 1.0f, 1.0f, 0.0f, farMaterial}});
  const fs::path path = tempDir() / name;
  std::ofstream(path, std::ios::binary) << text;
  return path.string();
}

json nearMaterial(double alpha, const std::string& mode, std::optional<double> cutoff = {}) {
  json m = test::gltfMaterial({kNearColor.r, kNearColor.g, kNearColor.b, alpha}, mode);
  if (cutoff) m["alphaCutoff"] = *cutoff;
  return m;
}

Camera camera() {
  Camera c;
  c.eye = {0.0f, 0.0f, 2.0f};
  c.target = {0.0f, 0.0f, 0.0f};
  c.up = {0.0f, 1.0f, 0.0f};
  c.fovYDegrees = static_cast<float>(kFov);
  return c;
}

struct Region {
  bool nearQuad, farQuad;
};
Region regionOf(int x, int y) {
  const double ndcX = (x + 0.5) / kSize * 2.0 - 1.0, ndcY = 1.0 - (y + 0.5) / kSize * 2.0;
  return {ndcX > 0.0, std::abs(ndcX) < 0.5 && std::abs(ndcY) < 0.5};
}

RenderOutput renderABuffer(const std::string& path, std::optional<float> alphaOverride = {}) {
  auto scene = loadScene(path);
  EXPECT_TRUE(scene.ok()) << scene.error().message;
  if (alphaOverride) scene->alphaOverride = *alphaOverride;
  RasterOptions ro;
  ro.width = kSize;
  ro.height = kSize;
  ro.threads = 2;
  auto frame = RasterFrame::build(*scene, camera(), ro);
  EXPECT_TRUE(frame.ok()) << frame.error().message;
  RenderOptions options;
  options.background = glm::vec3(kBackground);
  auto out = render(*frame, methodPreset("abuffer").value(), options);
  EXPECT_TRUE(out.ok()) << out.error().message;
  return std::move(out.value());
}

// Every pixel against the reference; `nearAlpha` empty: the near quad leaves no fragment.
// Returns how many pixels of each region were checked (nothing, B, A over B, A).
std::array<int, 4> expectImage(const RenderOutput& out, std::optional<double> nearAlpha,
                               double farAlpha, const std::string& what) {
  std::array<int, 4> checked{};
  EXPECT_EQ(out.image.width, kSize);
  EXPECT_EQ(out.image.height, kSize);
  EXPECT_EQ(out.depthComplexity.size(), static_cast<size_t>(kSize * kSize)) << what;
  if (out.depthComplexity.size() != static_cast<size_t>(kSize * kSize)) return checked;
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      const Region r = regionOf(x, y);
      std::vector<test::RefLayer> layers;
      if (r.nearQuad && nearAlpha) layers.push_back({kNearColor, *nearAlpha});
      if (r.farQuad) layers.push_back({kFarColor, farAlpha});
      const glm::dvec3 expected = test::refComposite(
          layers, test::refHeadlightCosine(x, y, kSize, kSize, kFov), kBackground);
      const glm::vec3 got = out.image.at(x, y);
      for (int ch = 0; ch < 3; ++ch)
        EXPECT_NEAR(got[ch], expected[ch], 2e-3)
            << what << ": pixel " << x << "," << y << " channel " << ch;
      EXPECT_EQ(out.depthComplexity[static_cast<size_t>(y * kSize + x)], layers.size())
          << what << ": fragments of pixel " << x << "," << y;
      ++checked[(r.nearQuad ? 2 : 0) + (r.farQuad ? 1 : 0)];
    }
  return checked;
}

void expectEveryRegionChecked(const std::array<int, 4>& checked) {
  // the layout above: 16 x 16 of the near quad alone at x >= 16 outside B, and so on
  EXPECT_EQ(checked[0], 16 * 32 - 8 * 16) << "background only";
  EXPECT_EQ(checked[1], 8 * 16) << "far quad alone";
  EXPECT_EQ(checked[3], 8 * 16) << "near over far";
  EXPECT_EQ(checked[2], 16 * 32 - 8 * 16) << "near quad alone";
}

TEST(AlphaModes, BlendControlShowsTheFarQuadThroughTheNearOne) {
  // the control for the tests below: with BLEND, the far quad shows through
  const RenderOutput out = renderABuffer(writeScene("blend.gltf", nearMaterial(0.4, "BLEND")));
  expectEveryRegionChecked(expectImage(out, 0.4, kFarAlpha, "BLEND"));
}

TEST(AlphaModes, OpaqueIgnoresTheFactorAlphaAndHidesWhatIsBehind) {
  const RenderOutput out = renderABuffer(writeScene("opaque.gltf", nearMaterial(0.4, "OPAQUE")));
  expectEveryRegionChecked(expectImage(out, 1.0, kFarAlpha, "OPAQUE"));
  // the far quad's fragment is still there (the A-buffer keeps it), it just contributes nothing:
  // the overlap equals the near quad over nothing at all
  const int x = 20, y = 12;
  ASSERT_TRUE(regionOf(x, y).nearQuad && regionOf(x, y).farQuad);
  const glm::dvec3 alone = test::refComposite(
      {{kNearColor, 1.0}}, test::refHeadlightCosine(x, y, kSize, kSize, kFov), glm::dvec3(0.0));
  for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(out.image.at(x, y)[ch], alone[ch], 2e-3);
}

struct MaskCase {
  const char* name;
  double alpha;
  std::optional<double> cutoff;  // empty: the glTF default 0.5
  bool kept;
};

class MaskMode : public ::testing::TestWithParam<MaskCase> {};

TEST_P(MaskMode, DropsBelowTheCutoffAndKeepsTheRestOpaque) {
  const MaskCase& c = GetParam();
  const RenderOutput out = renderABuffer(
      writeScene(std::string("mask_") + c.name + ".gltf", nearMaterial(c.alpha, "MASK", c.cutoff)));
  const auto checked = expectImage(out, c.kept ? std::optional<double>(1.0) : std::nullopt,
                                   kFarAlpha, std::string("MASK ") + c.name);
  expectEveryRegionChecked(checked);
  EXPECT_EQ(out.stats.fragmentsGenerated, c.kept ? 16u * 32u + 16u * 16u : 16u * 16u);
}

INSTANTIATE_TEST_SUITE_P(
    AlphaModes, MaskMode,
    ::testing::Values(MaskCase{"below_cutoff", 0.5, 0.6, false},
                      MaskCase{"above_cutoff", 0.7, 0.6, true},
                      MaskCase{"equal_to_cutoff", 0.5, 0.5, true},  // glTF: alpha >= cutoff
                      MaskCase{"below_default_cutoff", 0.45, std::nullopt, false},
                      MaskCase{"above_default_cutoff", 0.55, std::nullopt, true},
                      MaskCase{"zero_cutoff_keeps_alpha_zero", 0.0, 0.0, true}),
    [](const auto& info) { return std::string(info.param.name); });

TEST(AlphaModes, AlphaOverrideReplacesEveryMaterialsAlpha) {
  // OPAQUE near quad and BLEND far quad both become alpha 0.25
  const std::string opaque = writeScene("override_opaque.gltf", nearMaterial(0.4, "OPAQUE"));
  expectEveryRegionChecked(expectImage(renderABuffer(opaque, 0.25f), 0.25, 0.25, "OPAQUE, 0.25"));
  // a MASK fragment that passes its cutoff is not forced opaque: it gets the override alpha
  const std::string mask = writeScene("override_mask.gltf", nearMaterial(0.7, "MASK", 0.6));
  expectEveryRegionChecked(expectImage(renderABuffer(mask, 0.25f), 0.25, 0.25, "MASK, 0.25"));
  // ... and a MASK cutout keeps its shape: what its alpha test cuts away stays away
  const std::string cut = writeScene("override_mask_cut.gltf", nearMaterial(0.5, "MASK", 0.6));
  for (float override : {0.25f, 1.0f})
    expectEveryRegionChecked(expectImage(renderABuffer(cut, override), std::nullopt, override,
                                         "MASK below its cutoff, override"));
  // alpha 1 makes the BLEND near quad hide the far one
  const std::string blend = writeScene("override_blend.gltf", nearMaterial(0.4, "BLEND"));
  expectEveryRegionChecked(expectImage(renderABuffer(blend, 1.0f), 1.0, 1.0, "BLEND, 1"));
}

// The command line's --alpha, end to end: the PNG's sRGB codes against the reference.
TEST(AlphaModes, CliAlphaOptionOverridesEveryMaterialInTheWrittenImage) {
  const std::string scene = writeScene("cli_override.gltf", nearMaterial(0.4, "OPAQUE"));
  const fs::path dir = tempDir();
  auto run = [&](const std::string& extra, const std::string& name) {
    const std::string png = (dir / name).string();
    const test::CliRun r = test::runCli(
        "render " + scene + " --width 32 --height 32 --camera 0,0,2,0,0,0,0,1,0,90 " +
            "--background 0.3,0.6,0.2 --method abuffer --threads 2 -q " + extra + " -o " + png,
        dir);
    EXPECT_EQ(r.exitCode, 0) << r.err;
    auto image = readPng(png);
    EXPECT_TRUE(image.ok()) << png;
    return image.ok() ? image.value() : Image8{};
  };
  struct Case {
    std::string extra;
    double nearAlpha, farAlpha;
  };
  for (const Case& c : {Case{"", 1.0, kFarAlpha}, Case{"--alpha 0.25", 0.25, 0.25},
                        Case{"--alpha 0.8", 0.8, 0.8}}) {
    const Image8 image = run(c.extra, "cli_override.png");
    ASSERT_EQ(image.width, kSize) << c.extra;
    ASSERT_EQ(image.height, kSize) << c.extra;
    int checked = 0;
    for (int y = 0; y < kSize; ++y)
      for (int x = 0; x < kSize; ++x) {
        const Region r = regionOf(x, y);
        std::vector<test::RefLayer> layers;
        if (r.nearQuad) layers.push_back({kNearColor, c.nearAlpha});
        if (r.farQuad) layers.push_back({kFarColor, c.farAlpha});
        const glm::dvec3 expected = test::refComposite(
            layers, test::refHeadlightCosine(x, y, kSize, kSize, kFov), kBackground);
        for (int ch = 0; ch < 3; ++ch) {
          const int code = image.rgba[static_cast<size_t>((y * kSize + x) * 4 + ch)];
          EXPECT_NEAR(code, test::refSrgbCode(expected[ch]), 1)
              << c.extra << ": pixel " << x << "," << y << " channel " << ch;
          ++checked;
        }
      }
    EXPECT_EQ(checked, kSize * kSize * 3);
  }
}

}  // namespace
}  // namespace mfr
