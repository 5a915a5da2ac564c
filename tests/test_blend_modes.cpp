// Blend modes beyond over (core/blend_mode.hpp, method/blend_support.hpp): the node words of every
// mode; three layers (over in front, the mode under test in the middle, over behind) against the
// closed form written out here in double precision from the layers' 8-bit values, for every method
// that takes the mode; the hybrid tail's documented weighting of an additive node; additive layers
// in both submission orders; which methods refuse which modes (one line naming the method, the
// mode and what to use); every preset on a premultiplied scene; the `--blend` and `blend=` inputs.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "mfr/core/color.hpp"
#include "mfr/cpu/render.hpp"
#include "mfr/method/blend_support.hpp"
#include "mfr/method/method_options.hpp"
#include "mfr/scene/procedural.hpp"
#include "mfr/scene/scene_request.hpp"
#include "test_util.hpp"
#include "tsan/capture_cases.hpp"

namespace mfr {
namespace {

// an odd size: the centre pixel's view ray is the axis, so |n.v| = 1 and the headlight is 1
constexpr int kSize = 15;
constexpr size_t kCentre = 7 * kSize + 7;
const glm::vec3 kBg(0.2f, 0.4f, 0.6f);

struct Layer {
  float z;  // world z of the full-screen plane (further away: more negative)
  glm::vec4 color;
  BlendMode blend = BlendMode::Over;
};

Scene sceneOf(const std::vector<Layer>& layers) {
  std::vector<test::TestTriangle> tris;
  for (const Layer& l : layers) {
    const auto r = test::screenRect(-1, -1, kSize + 1, kSize + 1, kSize, l.z, l.color);
    tris.insert(tris.end(), r.begin(), r.end());
  }
  Scene s = test::makeScene(tris);
  for (size_t i = 0; i < layers.size(); ++i)
    for (size_t t = 0; t < 2; ++t) s.materials[2 * i + t].blend = layers[i].blend;
  return s;
}

RasterFrame frameOf(const std::vector<Layer>& layers) {
  return std::move(*test::buildFrame(sceneOf(layers), test::screenCamera(), kSize, kSize, 2));
}

MethodDesc methodOf(const std::string& preset, bool hybrid = false,
                    std::optional<uint32_t> k = {}) {
  MethodDesc m = methodPreset(preset).value();
  if (hybrid) m.compositing = Compositing::Hybrid;
  if (k) m.k = *k;
  return m;
}

Result<RenderOutput> run(const RasterFrame& frame, const MethodDesc& m) {
  RenderOptions o;
  o.background = kBg;
  if (m.allocation != AllocationPolicy::Unbounded) o.budgetBytes = 1u << 20;
  return render(frame, m, o);
}

double maxDiff(const ImageRGB& img, size_t p, glm::dvec3 expected) {
  const glm::dvec3 d = glm::abs(glm::dvec3(img.pixels[p]) - expected);
  return std::max({d.x, d.y, d.z});
}

// linear colours on 8-bit sRGB codes, so the headlight of the centre pixel (1) and the
// quantization leave them as they are
glm::vec3 codes(int r, int g, int b) {
  return {decodeSrgb8(static_cast<uint8_t>(r)), decodeSrgb8(static_cast<uint8_t>(g)),
          decodeSrgb8(static_cast<uint8_t>(b))};
}
const glm::vec3 kNearC = codes(200, 60, 30), kMidC = codes(40, 180, 90), kFarC = codes(30, 90, 220);
constexpr float kNearA = 0.6f, kFarA = 0.8f;  // alpha bytes 153 and 204: exactly 0.6 and 0.8

// The layers for `mode` in the middle: additive and multiply at alpha 1 (emission c, factor c);
// premultiplied at alpha 0.5 with colour c / 2 (straight colour c, alpha byte 128).
std::vector<Layer> threeLayers(BlendMode mode) {
  const glm::vec4 mid = mode == BlendMode::Premultiplied ? glm::vec4(kMidC * 0.5f, 0.5f)
                        : mode == BlendMode::Over        ? glm::vec4(kMidC, 0.6f)
                                                         : glm::vec4(kMidC, 1.0f);
  // submitted far, near, middle: the order must not matter
  return {{-3.0f, glm::vec4(kFarC, kFarA)}, {-0.5f, glm::vec4(kNearC, kNearA)}, {-1.5f, mid, mode}};
}

// Front to back, each mode's affine step written out: C = e + t C_behind.
glm::dvec3 threeLayerTruth(BlendMode mode) {
  const glm::dvec3 bg(kBg), nearC(kNearC), midC(kMidC), farC(kFarC);
  const glm::dvec3 far = double(kFarA) * farC + (1.0 - double(kFarA)) * bg;
  glm::dvec3 mid;
  switch (mode) {
    case BlendMode::Over:
      mid = 0.6 * midC + 0.4 * far;
      break;
    case BlendMode::Premultiplied: {
      const double a = 128.0 / 255.0;
      mid = a * midC + (1.0 - a) * far;
      break;
    }
    case BlendMode::Additive:
      mid = midC + far;
      break;
    case BlendMode::Multiply:
      mid = midC * far;
      break;
  }
  return double(kNearA) * nearC + (1.0 - double(kNearA)) * mid;
}

TEST(BlendModes, NodeWords) {
  const ColorTables& t = ColorTables::get();
  const glm::vec3 c(0.5f, 0.25f, 1.0f);
  const uint32_t rgb = packFragmentColor(t, c, 1.0f) & 0x00ffffffu;
  // over: the word of packFragmentColor; alpha bytes 0 and 1 are the other kinds' bytes
  EXPECT_EQ(packBlendedColor(t, BlendMode::Over, c, 0.6f), packFragmentColor(t, c, 0.6f));
  EXPECT_EQ(packBlendedColor(t, BlendMode::Over, c, 0.0f), 0u);  // adds nothing, hides nothing
  EXPECT_EQ(packBlendedColor(t, BlendMode::Over, c, 1.0f / 255.0f), rgb | (2u << 24));
  // additive: alpha byte 0, the emission a c
  EXPECT_EQ(packBlendedColor(t, BlendMode::Additive, c, 1.0f), rgb);
  EXPECT_EQ(packBlendedColor(t, BlendMode::Additive, c, 0.5f),
            packFragmentColor(t, c * 0.5f, 0.0f));
  // multiply: alpha byte 1, the factor 1 - a + a c
  EXPECT_EQ(packBlendedColor(t, BlendMode::Multiply, c, 1.0f), rgb | (1u << 24));
  EXPECT_EQ(packBlendedColor(t, BlendMode::Multiply, c, 0.0f),
            (packFragmentColor(t, glm::vec3(1.0f), 0.0f) & 0x00ffffffu) | (1u << 24));
  EXPECT_EQ(packBlendedColor(t, BlendMode::Multiply, glm::vec3(0.0f), 0.25f),
            (packFragmentColor(t, glm::vec3(0.75f), 0.0f) & 0x00ffffffu) | (1u << 24));
  // premultiplied: the straight colour with its alpha; at alpha 0 the colour is emission
  EXPECT_EQ(packBlendedColor(t, BlendMode::Premultiplied, c * 0.5f, 0.5f),
            packFragmentColor(t, c, 0.5f));
  EXPECT_EQ(packBlendedColor(t, BlendMode::Premultiplied, c, 0.0f), rgb);
  // a premultiplied colour above its alpha is clamped to it
  EXPECT_EQ(packBlendedColor(t, BlendMode::Premultiplied, glm::vec3(0.9f), 0.5f),
            packFragmentColor(t, glm::vec3(1.0f), 0.5f));
}

TEST(BlendModes, ThreeLayersMatchTheClosedForm) {
  struct Case {
    const char* preset;
    bool hybrid;
  };
  const Case cases[] = {{"abuffer", false},    {"fkb", false},         {"kplus-array", false},
                        {"kplus-heap", false}, {"kplus-sb", false},    {"kplus-sb", true},
                        {"optimal", false},    {"linked-list", false}, {"linked-list", true},
                        {"peel", false},       {"dual-peel", false},   {"aoit4", false},
                        {"aoit16", false}};
  for (BlendMode mode : kBlendModes) {
    const RasterFrame frame = frameOf(threeLayers(mode));
    const glm::dvec3 expected = threeLayerTruth(mode);
    for (const Case& c : cases) {
      const MethodDesc m = methodOf(c.preset, c.hybrid, 4);
      if ((blendModesOf(m) & blendBit(mode)) == 0) continue;
      auto out = run(frame, m);
      ASSERT_TRUE(out.ok()) << c.preset << " " << toString(mode) << ": " << out.error().message;
      EXPECT_EQ(out->stats.lost, 0u) << c.preset;
      EXPECT_LT(maxDiff(out->image, kCentre, expected), 2e-6)
          << c.preset << (c.hybrid ? " hybrid " : " ") << toString(mode);
    }
  }
}

TEST(BlendModes, WhoTakesWhichMode) {
  // the exact-order methods take every mode under the kbuffer rule; hybrid and the peers as the
  // table of blend_support.hpp says
  const uint32_t all = kEveryBlendMode, noMultiply = all & ~blendBit(BlendMode::Multiply);
  const uint32_t alphaWeighted = blendBit(BlendMode::Over) | blendBit(BlendMode::Premultiplied);
  EXPECT_EQ(blendModesOf(methodOf("abuffer")), all);
  EXPECT_EQ(blendModesOf(methodOf("kplus-sb")), all);
  EXPECT_EQ(blendModesOf(methodOf("linked-list")), all);
  EXPECT_EQ(blendModesOf(methodOf("dkb")), noMultiply);  // hybrid by default
  EXPECT_EQ(blendModesOf(methodOf("kplus-sb", true)), noMultiply);
  EXPECT_EQ(blendModesOf(methodOf("peel")), noMultiply);
  EXPECT_EQ(blendModesOf(methodOf("dual-peel")), noMultiply);
  EXPECT_EQ(blendModesOf(methodOf("aoit8")), noMultiply);
  for (const char* p : {"wboit", "mboit", "mboit8", "mboit-trig4-q16", "mlab", "stochastic",
                        "stochastic-strat", "hashed-alpha"})
    EXPECT_EQ(blendModesOf(methodOf(p)), alphaWeighted) << p;
}

TEST(BlendModes, AMethodRefusesAModeItCannotRepresentInOneLine) {
  const RasterFrame additive = frameOf(threeLayers(BlendMode::Additive));
  const RasterFrame multiply = frameOf(threeLayers(BlendMode::Multiply));
  for (const char* preset : {"wboit", "mboit", "mboit-trig3", "mlab"}) {
    auto out = run(additive, methodOf(preset));
    ASSERT_FALSE(out.ok()) << preset;
    const std::string& msg = out.error().message;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    EXPECT_EQ(msg.rfind(std::string(preset) + ": ", 0), 0u) << msg;
    EXPECT_NE(msg.find("additive"), std::string::npos) << msg;
    EXPECT_NE(msg.find("aoit"), std::string::npos) << msg;  // what to use instead
  }
  for (const char* preset : {"peel", "aoit4", "wboit"}) {
    auto out = run(multiply, methodOf(preset));
    ASSERT_FALSE(out.ok()) << preset;
    EXPECT_NE(out.error().message.find("multiply"), std::string::npos) << out.error().message;
  }
  auto hybrid = run(multiply, methodOf("kplus-sb", true));
  ASSERT_FALSE(hybrid.ok());
  EXPECT_NE(hybrid.error().message.find("--composite kbuffer"), std::string::npos)
      << hybrid.error().message;
  EXPECT_FALSE(run(multiply, methodOf("dkb")).ok());
}

TEST(BlendModes, EveryPresetTakesPremultipliedAlpha) {
  const RasterFrame frame = frameOf(threeLayers(BlendMode::Premultiplied));
  for (const PresetInfo& p : presetTable()) {
    auto out = run(frame, methodPreset(p.name).value());
    EXPECT_TRUE(out.ok()) << p.name << ": " << (out.ok() ? "" : out.error().message);
  }
}

TEST(BlendModes, HybridTailWeightsAnAdditiveNodeLikeItsOverFragments) {
  // k = 1: the near layer is the core; the additive layer and the far layer are the tail, whose
  // colour sum holds e + a3 c3 and alpha sum a3 (method_math.h hybridTailAddNode)
  const RasterFrame frame = frameOf(threeLayers(BlendMode::Additive));
  for (const char* preset : {"fkb", "kplus-array"}) {
    auto out = run(frame, methodOf(preset, true, 1));
    ASSERT_TRUE(out.ok()) << out.error().message;
    const glm::dvec3 sum = glm::dvec3(kMidC) + double(kFarA) * glm::dvec3(kFarC);
    const double alphaSum = kFarA, tailAlpha = 1.0 - std::pow(1.0 - alphaSum / 2.0, 2.0);
    const glm::dvec3 behind = tailAlpha * sum / alphaSum + (1.0 - tailAlpha) * glm::dvec3(kBg);
    const glm::dvec3 expected =
        double(kNearA) * glm::dvec3(kNearC) + (1.0 - double(kNearA)) * behind;
    EXPECT_LT(maxDiff(out->image, kCentre, expected), 2e-6) << preset;
    // an additive tail with no alpha adds its emission unweighted
    const RasterFrame glow = frameOf(
        {{-0.5f, glm::vec4(kNearC, kNearA)}, {-1.5f, glm::vec4(kMidC, 1.0f), BlendMode::Additive}});
    auto lit = run(glow, methodOf(preset, true, 1));
    ASSERT_TRUE(lit.ok()) << lit.error().message;
    const glm::dvec3 litExpected = double(kNearA) * glm::dvec3(kNearC) +
                                   (1.0 - double(kNearA)) * (glm::dvec3(kMidC) + glm::dvec3(kBg));
    EXPECT_LT(maxDiff(lit->image, kCentre, litExpected), 2e-6) << preset;
  }
}

TEST(BlendModes, AdditiveLayersAloneAreOrderIndependent) {
  const Layer a{-0.5f, glm::vec4(codes(60, 20, 10), 1.0f), BlendMode::Additive};
  const Layer b{-1.0f, glm::vec4(codes(10, 70, 20), 1.0f), BlendMode::Additive};
  const Layer c{-2.0f, glm::vec4(codes(15, 25, 90), 1.0f), BlendMode::Additive};
  const RasterFrame forward = frameOf({a, b, c}), backward = frameOf({c, b, a});
  const glm::dvec3 expected =
      glm::dvec3(kBg) + glm::dvec3(a.color) + glm::dvec3(b.color) + glm::dvec3(c.color);
  for (const char* preset :
       {"abuffer", "kplus-array", "linked-list", "peel", "dual-peel", "aoit4"}) {
    auto f = run(forward, methodOf(preset, false, 4));
    auto r = run(backward, methodOf(preset, false, 4));
    ASSERT_TRUE(f.ok() && r.ok()) << preset;
    EXPECT_LT(maxDiff(f->image, kCentre, expected), 2e-6) << preset;
    if (std::string(preset) != "aoit4") {  // the sorted methods: bit-identical
      EXPECT_EQ(f->image.pixels, r->image.pixels) << preset;
      continue;
    }
    for (size_t p = 0; p < f->image.pixels.size(); ++p)  // AOIT sums in arrival order
      ASSERT_LT(maxDiff(r->image, p, glm::dvec3(f->image.pixels[p])), 1e-6) << p;
  }
}

TEST(BlendModes, Inputs) {
  auto o = parseBlendOverride("additive", "--blend");
  ASSERT_TRUE(o.ok());
  EXPECT_TRUE(o->material.empty());
  EXPECT_EQ(o->mode, BlendMode::Additive);
  o = parseBlendOverride("glass pane=multiply", "--blend");
  ASSERT_TRUE(o.ok());
  EXPECT_EQ(o->material, "glass pane");
  EXPECT_EQ(o->mode, BlendMode::Multiply);
  for (const char* bad : {"glow", "=additive", "glass=", "glass=screen"}) {
    auto e = parseBlendOverride(bad, "--blend");
    ASSERT_FALSE(e.ok()) << bad;
    EXPECT_EQ(e.error().message.rfind("--blend ", 0), 0u) << e.error().message;
  }

  // a procedural scene's blend= sets every material; a bad value names the parameter
  auto particles = makeProceduralScene("procedural:particles?count=10&blend=additive", 1);
  ASSERT_TRUE(particles.ok()) << particles.error().message;
  EXPECT_EQ(particles->blendModes(), blendBit(BlendMode::Additive));
  auto bad = makeProceduralScene("procedural:particles?blend=glow", 1);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message.find("'blend'"), std::string::npos) << bad.error().message;

  // --blend MATERIAL=MODE: applied in order; a name no material has is an error naming it
  Scene s = sceneOf(threeLayers(BlendMode::Over));
  SceneRequest r;
  r.blend = {"premultiplied", "material 1=multiply"};
  ASSERT_TRUE(checkSceneRequest(r).ok());
  ASSERT_TRUE(applyToScene(r, s).ok());
  EXPECT_EQ(s.materials[0].blend, BlendMode::Premultiplied);
  EXPECT_EQ(s.materials[1].blend, BlendMode::Multiply);
  r.blend = {"lens=additive"};
  auto missing = applyToScene(r, s);
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.error().message.find("'lens'"), std::string::npos) << missing.error().message;
  EXPECT_EQ(missing.error().message.find('\n'), std::string::npos);
  r.blend = {"sideways"};
  EXPECT_FALSE(checkSceneRequest(r).ok());
}

}  // namespace
}  // namespace mfr
