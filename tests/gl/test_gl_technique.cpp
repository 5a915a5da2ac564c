// The GL engine's technique table (mfr/gl/gl_technique.hpp): every preset the library names runs
// as the technique its paper describes, the table lists the techniques in the enum's order, and a
// method outside the GL engine is one line naming it. No GL context needed.
#include <gtest/gtest.h>

#include <map>
#include <string>

#include "mfr/gl/gl_technique.hpp"
#include "mfr/method/method.hpp"

namespace {

using namespace mfr;
using namespace mfr::gl;

// what each preset is, written from the papers rather than from classifyGl's rules
GlTechnique expectedTechnique(const std::string& preset) {
  static const std::map<std::string, GlTechnique> peers = {
      {"abuffer", GlTechnique::ABuffer},
      {"wboit", GlTechnique::Wboit},
      {"mboit", GlTechnique::Mboit},
      {"mboit6", GlTechnique::Mboit},
      {"mboit8", GlTechnique::Mboit},
      {"mlab", GlTechnique::Mlab},
      {"mboit-trig3", GlTechnique::Mboit},
      {"mboit-trig4", GlTechnique::Mboit},
      {"mboit-q16", GlTechnique::Mboit},
      {"mboit6-q16", GlTechnique::Mboit},
      {"mboit8-q16", GlTechnique::Mboit},
      {"mboit-trig3-q16", GlTechnique::Mboit},
      {"mboit-trig4-q16", GlTechnique::Mboit},
      {"aoit4", GlTechnique::Aoit},
      {"aoit8", GlTechnique::Aoit},
      {"aoit16", GlTechnique::Aoit},
      {"linked-list", GlTechnique::LinkedList},
      {"peel", GlTechnique::Peel},
      {"dual-peel", GlTechnique::Peel},
      {"dfaoit", GlTechnique::Dfaoit},
      {"stochastic", GlTechnique::Stochastic},
      {"stochastic-strat", GlTechnique::Stochastic},
      {"hashed-alpha", GlTechnique::HashedAlpha}};
  const auto it = peers.find(preset);
  return it == peers.end() ? GlTechnique::KBuffer : it->second;  // the k-buffer family
}

TEST(GlTechnique, EveryPresetRunsAsItsTechnique) {
  int presets = 0, occupancyForms = 0;
  for (const std::string& name : presetNames()) {
    const MethodDesc method = methodPreset(name).value();
    auto t = classifyGl(method);
    ASSERT_TRUE(t.ok()) << name << ": " << t.error().message;
    EXPECT_EQ(*t, expectedTechnique(name)) << name << " runs as " << toString(*t);
    ++presets;
    auto culled = methodPreset(name + "+occupancy");  // the k-buffer family's occupancy form
    if (!culled) continue;
    auto tc = classifyGl(culled.value());
    ASSERT_TRUE(tc.ok()) << name << "+occupancy: " << tc.error().message;
    EXPECT_EQ(*tc, GlTechnique::KBuffer) << name << "+occupancy";
    ++occupancyForms;
  }
  // every preset: 13 of the k-buffer family, the A-buffer, linked-list, 21 peers
  EXPECT_EQ(presets, 36);
  EXPECT_EQ(occupancyForms, 13);
}

TEST(GlTechnique, EitherCompositingOfTheKBufferFamily) {
  for (const char* name : {"fkb", "kplus-heap", "kplus-sb+occupancy", "vkb", "dkb", "optimal"}) {
    MethodDesc method = methodPreset(name).value();
    for (Compositing c : {Compositing::KBuffer, Compositing::Hybrid}) {
      method.compositing = c;
      auto t = classifyGl(method);
      ASSERT_TRUE(t.ok()) << name << ": " << t.error().message;
      EXPECT_EQ(*t, GlTechnique::KBuffer) << name;
    }
  }
}

TEST(GlTechnique, TableRowsFollowTheEnum) {
  const auto rows = glTechniques();
  ASSERT_EQ(rows.size(), 11u);
  for (size_t i = 0; i < rows.size(); ++i) {
    EXPECT_EQ(static_cast<size_t>(rows[i].technique), i);
    EXPECT_EQ(&techniqueInfo(rows[i].technique), &rows[i]);
    for (const char* field : {rows[i].name, rows[i].passes, rows[i].capture, rows[i].resolve,
                              rows[i].perPixel, rows[i].presets})
      EXPECT_GT(std::string(field).size(), 0u) << i;
  }
  EXPECT_EQ(std::string(toString(GlTechnique::Mboit)), "mboit");
  EXPECT_EQ(std::string(toString(GlTechnique::KBuffer)), "kbuffer");
}

TEST(GlTechnique, CombinationsOutsideTheGlEngineAreOneLineErrors) {
  auto expectRefused = [](MethodDesc m, const std::string& what) {
    m.name = "custom-" + what;
    auto t = classifyGl(m);
    ASSERT_FALSE(t.ok()) << what << " ran as " << toString(*t);
    EXPECT_NE(t.error().message.find("--engine gl: method custom-" + what), std::string::npos)
        << t.error().message;
    EXPECT_NE(t.error().message.find("not in the GL engine"), std::string::npos);
    EXPECT_EQ(t.error().message.find('\n'), std::string::npos);
  };
  MethodDesc m = methodPreset("mlab").value();
  m.occupancyWords = 1;
  expectRefused(m, "mlab-occupancy");
  m = methodPreset("abuffer").value();
  m.occupancyWords = 2;
  expectRefused(m, "abuffer-occupancy");
  m = methodPreset("linked-list").value();
  m.occupancyWords = 1;
  expectRefused(m, "linked-list-occupancy");
  m = methodPreset("abuffer").value();
  m.compositing = Compositing::Hybrid;
  expectRefused(m, "abuffer-hybrid");
  m = methodPreset("wboit").value();
  m.occupancyWords = 1;
  expectRefused(m, "wboit-occupancy");
  m = methodPreset("fkb").value();
  m.store = StoreChoice::Append;
  expectRefused(m, "fkb-append");
  m = methodPreset("fkb").value();
  m.store = StoreChoice::PerPixel;  // K+B-SB picks per pixel from an allocation a fixed k lacks
  expectRefused(m, "fkb-perpixel");
  m = methodPreset("kplus-heap").value();
  m.occupancyWords = 65;
  expectRefused(m, "occupancy-65");
  m = methodPreset("mboit").value();
  m.allocation = AllocationPolicy::FixedK;
  expectRefused(m, "mboit-nodes");
  m = methodPreset("peel").value();
  m.allocation = AllocationPolicy::FixedK;
  expectRefused(m, "peel-nodes");
}

}  // namespace
