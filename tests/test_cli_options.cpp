// Command-line options end to end, each checked against an independent expectation: --orbit,
// --orbit-view, --zoom, --capture parallel, --occupancy-d, --transmission-floor, mfr dataset
// --budget-steps, mfr train --l1 --l2 --batch --log --loss-curve, and render --model.
// Every run is tiny (at most 64 x 64 pixels, a few epochs).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_runner.hpp"
#include "gltf_quads.hpp"
#include "mfr/core/image.hpp"
#include "mfr/learn/dataset.hpp"
#include "mfr/learn/model_file.hpp"
#include "reference_shading.hpp"

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

fs::path tempDir() {
  static const fs::path dir = mfr::test::processTempDir("mfr_cli_options_test");
  return dir;
}

std::string path(const std::string& name) {
  return (tempDir() / name).string();
}

mfr::test::CliRun runCli(const std::string& args) {
  return mfr::test::runCli(args, tempDir());
}

// Runs `mfr ARGS` and expects success.
void runOk(const std::string& args) {
  const mfr::test::CliRun r = runCli(args);
  ASSERT_FALSE(r.signaled) << args;
  ASSERT_EQ(r.exitCode, 0) << args << "\n" << r.err;
}

std::string readBytes(const std::string& p) {
  std::ifstream f(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), {});
}

mfr::Image8 readImage(const std::string& p) {
  auto image = mfr::readPng(p);
  EXPECT_TRUE(image.ok()) << p << ": " << (image.ok() ? "" : image.error().message);
  return image.ok() ? image.value() : mfr::Image8{};
}

json readJson(const std::string& p) {
  std::ifstream f(p);
  EXPECT_TRUE(f.good()) << p;
  return json::parse(f, nullptr, /*allow_exceptions=*/false);
}

// Number of pixels whose RGB differs; -1 when the sizes differ or an image is empty.
long differingPixels(const mfr::Image8& a, const mfr::Image8& b) {
  if (a.width != b.width || a.height != b.height || a.rgba.empty() ||
      a.rgba.size() != b.rgba.size())
    return -1;
  long n = 0;
  for (size_t i = 0; i < a.rgba.size(); i += 4)
    n += a.rgba[i] != b.rgba[i] || a.rgba[i + 1] != b.rgba[i + 1] || a.rgba[i + 2] != b.rgba[i + 2];
  return n;
}

// ---------------------------------------------------------------------------------------------
// --orbit, --orbit-view

const char* kOrbitScene = "'procedural:hairball?strands=150'";
const std::string kOrbitCommon = std::string("render ") + kOrbitScene +
                                 " --width 32 --height 32 --method abuffer --threads 2 -q ";

// Every output makes its missing folder, as the images always did: the statistics, a dataset,
// a model and its log (not only -o of render), so no run writes one file and fails on the next.
TEST(CliOptions, EveryOutputMakesItsMissingFolder) {
  const fs::path dir = tempDir() / "made";
  fs::remove_all(dir);
  const std::string d = dir.string();
  auto r = runCli("render procedural:layers --width 16 --height 16 -q -o " + d +
                  "/a/x.png --stats-json " + d + "/b/s.json");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_TRUE(fs::is_regular_file(dir / "a" / "x.png"));
  EXPECT_TRUE(fs::is_regular_file(dir / "b" / "s.json"));
  r = runCli("dataset procedural:layers --width 16 --height 16 --budget-steps 1 -q -o " + d +
             "/c/x.mfrds");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  r = runCli("train " + d + "/c/x.mfrds --epochs 1 -q -o " + d + "/d/m.mfrnn --log " + d +
             "/e/log.csv");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_TRUE(fs::is_regular_file(dir / "d" / "m.mfrnn"));
  EXPECT_TRUE(fs::is_regular_file(dir / "e" / "log.csv"));
  // a file where the folder should be is still one line naming the path
  r = runCli("render procedural:layers --width 16 --height 16 -q -o " + d + "/f.png --stats-json " +
             d + "/a/x.png/s.json");
  EXPECT_EQ(r.exitCode, 1);
  EXPECT_NE(r.err.find("a/x.png/s.json: cannot open for writing"), std::string::npos) << r.err;
  fs::remove_all(dir);
}

TEST(CliOptions, OrbitWritesNSuffixedViewsThatDiffer) {
  const fs::path dir = tempDir() / "orbit";
  fs::create_directories(dir);
  runOk(kOrbitCommon + "--orbit 4 -o " + (dir / "o.png").string() + " --depth-complexity " +
        (dir / "n.png").string() + " --stats-json " + (dir / "s.json").string());
  EXPECT_FALSE(fs::exists(dir / "o.png")) << "several views: only suffixed names";
  EXPECT_FALSE(fs::exists(dir / "o_v004.png")) << "N views, not N + 1";
  std::vector<mfr::Image8> views;
  for (const char* name : {"o_v000.png", "o_v001.png", "o_v002.png", "o_v003.png"}) {
    views.push_back(readImage((dir / name).string()));
    ASSERT_EQ(views.back().width, 32) << name;
    ASSERT_EQ(views.back().height, 32) << name;
  }
  for (const char* name : {"n_v000.png", "n_v003.png"})
    EXPECT_TRUE(fs::exists(dir / name)) << "maps get the suffix too: " << name;
  int pairs = 0;
  for (size_t a = 0; a < views.size(); ++a)
    for (size_t b = a + 1; b < views.size(); ++b, ++pairs)
      EXPECT_GT(differingPixels(views[a], views[b]), 20) << "views " << a << " and " << b;
  EXPECT_EQ(pairs, 6);
  // the statistics: one record per view, in order
  const json stats = readJson((dir / "s.json").string());
  ASSERT_TRUE(stats.is_array());
  ASSERT_EQ(stats.size(), 4u);
  for (int v = 0; v < 4; ++v) {
    EXPECT_EQ(stats[static_cast<size_t>(v)]["view"].get<int>(), v);
    char name[32];
    std::snprintf(name, sizeof name, "o_v%03d.png", v);
    EXPECT_EQ(stats[static_cast<size_t>(v)]["image"].get<std::string>(), (dir / name).string());
  }
}

TEST(CliOptions, OrbitViewEqualsThatViewOfTheFullOrbitByteForByte) {
  const fs::path dir = tempDir() / "orbit_view";
  fs::create_directories(dir);
  runOk(kOrbitCommon + "--orbit 3 -o " + (dir / "all.png").string());
  int compared = 0;
  for (int i = 0; i < 3; ++i) {
    const std::string single = (dir / ("single" + std::to_string(i) + ".png")).string();
    runOk(kOrbitCommon + "--orbit 3 --orbit-view " + std::to_string(i) + " -o " + single);
    char name[32];
    std::snprintf(name, sizeof name, "all_v%03d.png", i);
    const std::string full = readBytes((dir / name).string());
    ASSERT_FALSE(full.empty()) << name;
    EXPECT_EQ(readBytes(single), full) << "--orbit-view " << i;
    ++compared;
  }
  EXPECT_EQ(compared, 3);
  // the variable k-buffer too: view I's Fresnel term uses view I - 1's nearest |n.v| either way
  for (int i = 1; i < 3; ++i) {
    const std::string vkb = std::string("render ") + kOrbitScene +
                            " --width 32 --height 32 --method vkb --budget 24KB --threads 2 -q " +
                            "--orbit 3 ";
    runOk(vkb + "-o " + (dir / "vkb_all.png").string());
    const std::string single = (dir / "vkb_single.png").string();
    runOk(vkb + "--orbit-view " + std::to_string(i) + " -o " + single);
    char name[32];
    std::snprintf(name, sizeof name, "vkb_all_v%03d.png", i);
    EXPECT_EQ(readBytes(single), readBytes((dir / name).string())) << "vkb --orbit-view " << i;
  }
  // and one view of the orbit is not the plain camera's image (the orbit did move the camera)
  const std::string plain = path("orbit_plain.png");
  runOk(kOrbitCommon + "-o " + plain);
  EXPECT_GT(differingPixels(readImage(plain), readImage((dir / "single1.png").string())), 20);
}

// ---------------------------------------------------------------------------------------------
// --zoom: a unit square facing the camera; its covered pixels counted by hand.

// Pixels along one axis whose centre falls inside the square's projection.
int projectedSpan(int size, double halfExtent, double distance, double fovDegrees) {
  const double edge = halfExtent / (distance * std::tan(fovDegrees * M_PI / 360.0));  // in NDC
  int n = 0;
  for (int x = 0; x < size; ++x) {
    const double ndc = (x + 0.5) / size * 2.0 - 1.0;
    // the test is only fair away from pixel centres (snapping moves edges by 1/256 pixel)
    EXPECT_GT(std::abs(std::abs(ndc) - edge) * size / 2.0, 0.05) << "edge on a pixel centre";
    n += std::abs(ndc) < edge;
  }
  return n;
}

TEST(CliOptions, ZoomMovesTheCameraCloserAndTheSquareCoversTheExpectedPixels) {
  const std::string obj = path("square.obj");
  std::ofstream(obj) << "v -0.5 -0.5 0\nv 0.5 -0.5 0\nv 0.5 0.5 0\nv -0.5 0.5 0\nf 1 2 3 4\n";
  const int size = 64;
  std::map<double, uint64_t> covered;
  std::map<double, mfr::Image8> images;
  for (const double zoom : {0.5, 1.0, 2.0}) {
    const std::string png = path("zoom.png"), stats = path("zoom.json");
    std::ostringstream args;
    args << "render " << obj << " --width " << size << " --height " << size
         << " --camera 0,0,4,0,0,0,0,1,0,45 --background 0,0,0 --method abuffer --threads 2 -q "
         << "--zoom " << zoom << " -o " << png << " --stats-json " << stats;
    runOk(args.str());
    const json j = readJson(stats);
    ASSERT_TRUE(j.contains("covered_pixels")) << j.dump();
    covered[zoom] = j["covered_pixels"].get<uint64_t>();
    images[zoom] = readImage(png);
    const int span = projectedSpan(size, 0.5, 4.0 / zoom, 45.0);
    EXPECT_EQ(covered[zoom], static_cast<uint64_t>(span * span)) << "--zoom " << zoom;
    EXPECT_EQ(j["fragments_generated"].get<uint64_t>(), covered[zoom]) << "one layer";
  }
  // by hand: the square's half-width over the view's half-width at distance 4 / Z is
  // 0.5 / (4 / Z x tan 22.5 deg) = 0.151, 0.302, 0.604 of the 32-pixel half-image: 4.83, 9.66 and
  // 19.31 pixels either side of the centre line 32, so pixel centres 27.5..36.5, 22.5..41.5 and
  // 13.5..50.5 are inside
  EXPECT_EQ(covered[0.5], 10u * 10u);
  EXPECT_EQ(covered[1.0], 20u * 20u);
  EXPECT_EQ(covered[2.0], 38u * 38u);
  // over black, a pixel is lit exactly when covered; a pixel covered at both zooms has the same
  // colour (the headlight term depends on the pixel's ray, not on the distance), so the images
  // differ in exactly the pixels the larger square adds
  for (const auto& [zoom, image] : images) {
    long lit = 0;
    for (size_t i = 0; i < image.rgba.size(); i += 4) lit += image.rgba[i] != 0;
    EXPECT_EQ(lit, static_cast<long>(covered[zoom])) << "--zoom " << zoom;
  }
  EXPECT_EQ(differingPixels(images[1.0], images[2.0]), static_cast<long>(38 * 38 - 20 * 20));
  EXPECT_EQ(differingPixels(images[0.5], images[1.0]), static_cast<long>(20 * 20 - 10 * 10));
}

// ---------------------------------------------------------------------------------------------
// --capture parallel

TEST(CliOptions, ParallelCaptureKeepsTheSameFragmentsAndImageAsTileCapture) {
  int compared = 0;
  for (const char* method : {"kplus-heap", "kplus-array", "kplus-sb", "kplus-dynamic"}) {
    std::map<std::string, json> stats;
    std::map<std::string, std::string> images;
    for (const char* capture : {"tile", "parallel"}) {
      const std::string png = path(std::string("capture_") + capture + ".png");
      const std::string js = path(std::string("capture_") + capture + ".json");
      runOk(std::string("render 'procedural:hairball?strands=300' --width 64 --height 64 ") +
            "--threads 4 --budget 120KB --composite kbuffer -q --method " + method + " --capture " +
            capture + " -o " + png + " --stats-json " + js);
      stats[capture] = readJson(js);
      images[capture] = png;
    }
    const json& t = stats["tile"];
    const json& p = stats["parallel"];
    EXPECT_EQ(t["capture"], "tile");
    EXPECT_EQ(p["capture"], "parallel");
    EXPECT_GT(t["fragments_lost"].get<uint64_t>(), 0u) << method << ": the budget must bind";
    EXPECT_GT(t["fragments_captured"].get<uint64_t>(), 0u) << method;
    for (const char* key : {"fragments_generated", "fragments_captured", "fragments_lost",
                            "bytes_used", "k_min", "k_max", "fragment_slots"})
      EXPECT_EQ(t[key], p[key]) << method << " " << key;
    const mfr::Image8 a = readImage(images["tile"]), b = readImage(images["parallel"]);
    EXPECT_EQ(differingPixels(a, b), 0) << method << ": kbuffer images must be equal";
    ++compared;
  }
  EXPECT_EQ(compared, 4);
}

// ---------------------------------------------------------------------------------------------
// --occupancy-d with a +occupancy preset

TEST(CliOptions, OccupancyDChargesTwelvePlusFourDBytesPerPixelAndLosesNothingItShouldKeep) {
  const int width = 48, height = 40;  // not square: catches width/height mix-ups
  const std::string common =
      "render 'procedural:hairball?strands=300' --width 48 --height 40 --threads 2 --k 3 "
      "--composite kbuffer -q ";
  const std::string basePng = path("occ_base.png"), baseJson = path("occ_base.json");
  runOk(common + "--method kplus-array -o " + basePng + " --stats-json " + baseJson);
  const json base = readJson(baseJson);
  EXPECT_FALSE(base["bytes_by_category"].contains("occupancy"));
  std::map<int, uint64_t> used;
  for (const int d : {1, 2, 5}) {
    const std::string png = path("occ.png"), js = path("occ.json");
    runOk(common + "--method kplus-array+occupancy --occupancy-d " + std::to_string(d) + " -o " +
          png + " --stats-json " + js);
    const json j = readJson(js);
    // zn f32, zf f32, j_k u32 and d u32 bitmap words per pixel
    const uint64_t expected = static_cast<uint64_t>(width * height) * (4 + 4 + 4 + 4 * d);
    ASSERT_TRUE(j["bytes_by_category"].contains("occupancy")) << j.dump();
    EXPECT_EQ(j["bytes_by_category"]["occupancy"].get<uint64_t>(), expected) << "d=" << d;
    EXPECT_EQ(j["bytes_used"].get<uint64_t>(), base["bytes_used"].get<uint64_t>() + expected)
        << "d=" << d << ": with a fixed k only the occupancy words are added";
    used[d] = j["bytes_used"].get<uint64_t>();
    EXPECT_GT(j["culled"]["occupancy"].get<uint64_t>(), 0u) << "d=" << d << ": culling ran";
    EXPECT_EQ(j["fragments_captured"], base["fragments_captured"]) << "d=" << d;
    // occupancy culling never rejects one of the k nearest (Lemma 2.1): the image is unchanged
    EXPECT_EQ(differingPixels(readImage(png), readImage(basePng)), 0) << "d=" << d;
  }
  EXPECT_EQ(used[2] - used[1], static_cast<uint64_t>(4 * width * height));
  EXPECT_EQ(used[5] - used[1], static_cast<uint64_t>(16 * width * height));
}

TEST(CliOptions, OccupancyDUnderABudgetComesOutOfTheNodePool) {
  // fkb+occupancy under M = 44 KiB on 32 x 32 pixels: S_p = 4 (counter) + 12 + 4d (occupancy),
  // F(M) = floor((M - 1024 S_p) / 8), k = floor(F / 1024):
  //   d = 1: F = (45056 - 20480) / 8 = 3072, k = 3;  d = 3: F = (45056 - 28672) / 8 = 2048, k = 2
  const uint64_t pixels = 32 * 32;
  const std::map<int, uint32_t> expectedK = {{1, 3u}, {3, 2u}};
  for (const auto& [d, k] : expectedK) {
    const std::string js = path("occ_budget.json");
    runOk(
        "render 'procedural:hairball?strands=300' --width 32 --height 32 --threads 2 "
        "--method fkb+occupancy --budget 44KB --composite kbuffer -q -o " +
        path("occ_budget.png") + " --occupancy-d " + std::to_string(d) + " --stats-json " + js);
    const json j = readJson(js);
    EXPECT_EQ(j["bytes_by_category"]["occupancy"].get<uint64_t>(), pixels * (12 + 4 * d));
    EXPECT_EQ(j["k"].get<uint32_t>(), k) << "d=" << d;
    EXPECT_EQ(j["fragment_slots"].get<uint64_t>(), pixels * k) << "d=" << d;
    EXPECT_EQ(j["bytes_used"].get<uint64_t>(), pixels * (4 + 12 + 4 * d) + pixels * k * 8)
        << "d=" << d;
    EXPECT_LE(j["bytes_used"].get<uint64_t>(), 44u * 1024u);
  }
}

// ---------------------------------------------------------------------------------------------
// --transmission-floor: a KHR_materials_transmission quad beside a plain BLEND quad.

TEST(CliOptions, TransmissionFloorSetsTheAlphaOfFullyTransmissiveMaterialsOnly) {
  using mfr::test::GltfQuad;
  json glass = mfr::test::gltfMaterial({1.0, 1.0, 1.0, 1.0}, "OPAQUE");
  glass["extensions"] = {{"KHR_materials_transmission", {{"transmissionFactor", 1.0}}}};
  const json plain = mfr::test::gltfMaterial({1.0, 1.0, 1.0, 0.5}, "BLEND");
  const std::string gltf = path("transmission.gltf");
  std::ofstream(gltf, std::ios::binary)
      << mfr::test::gltfWithQuads({GltfQuad{-1.5f, -0.5f, -0.5f, 0.5f, 0.0f, glass},
                                   GltfQuad{0.5f, -0.5f, 1.5f, 0.5f, 0.0f, plain}});
  const int size = 32;
  const int glassX = 8, plainX = 23, y = 16;  // pixel centres inside each quad
  std::map<double, mfr::Image8> images;
  for (const double floor : {0.1, 0.3, 0.6}) {
    const std::string png = path("transmission.png");
    std::ostringstream args;
    args << "render " << gltf << " --width 32 --height 32 --camera 0,0,2,0,0,0,0,1,0,90 "
         << "--background 0,0,0 --method abuffer --threads 2 -q --transmission-floor " << floor
         << " -o " << png;
    runOk(args.str());
    images[floor] = readImage(png);
    ASSERT_EQ(images[floor].width, size);
    // alpha = max(floor, 1 - 1) = floor, over black: alpha x white x light
    for (const auto& [x, alpha] : {std::pair{glassX, floor}, std::pair{plainX, 0.5}}) {
      const double cosine = mfr::test::refHeadlightCosine(x, y, size, size, 90.0);
      const glm::dvec3 expected =
          mfr::test::refComposite({{glm::dvec3(1.0), alpha}}, cosine, glm::dvec3(0.0));
      for (int ch = 0; ch < 3; ++ch)
        EXPECT_NEAR(images[floor].rgba[static_cast<size_t>((y * size + x) * 4 + ch)],
                    mfr::test::refSrgbCode(expected[ch]), 1)
            << "floor " << floor << " pixel " << x << " channel " << ch;
    }
  }
  // the floor changes the glass and nothing else
  for (const auto& [a, b] : {std::pair{0.1, 0.3}, std::pair{0.3, 0.6}}) {
    const mfr::Image8& ia = images[a];
    const mfr::Image8& ib = images[b];
    long glassDiffers = 0, otherDiffers = 0;
    for (int py = 0; py < size; ++py)
      for (int px = 0; px < size; ++px) {
        const size_t i = static_cast<size_t>((py * size + px) * 4);
        const bool differs = ia.rgba[i] != ib.rgba[i];
        (px < size / 2 ? glassDiffers : otherDiffers) += differs;
      }
    EXPECT_EQ(glassDiffers, 8 * 8) << "floors " << a << " and " << b << ": the glass quad's pixels";
    EXPECT_EQ(otherDiffers, 0) << "floors " << a << " and " << b;
  }
}

// ---------------------------------------------------------------------------------------------
// mfr dataset --budget-steps, mfr train, render --model

const char* kDatasetScenes = "'procedural:layers?k=4' 'procedural:spheres?count=3'";

// Covered pixels of a scene at 32 x 32 from the abuffer's statistics.
uint64_t coveredPixels(const std::string& scene) {
  const std::string js = path("covered.json");
  const mfr::test::CliRun r =
      runCli("render " + scene + " --width 32 --height 32 --method abuffer -q -o " +
             path("covered.png") + " --stats-json " + js);
  EXPECT_EQ(r.exitCode, 0) << r.err;
  return readJson(js)["covered_pixels"].get<uint64_t>();
}

// A dataset of both scenes, every covered pixel sampled, N budget steps (built once per N).
const std::string& dataset(int steps) {
  static std::map<int, std::string> files;
  auto it = files.find(steps);
  if (it != files.end()) return it->second;
  const std::string out = path("steps" + std::to_string(steps) + ".mfrds");
  const mfr::test::CliRun r = runCli(std::string("dataset ") + kDatasetScenes +
                                     " --width 32 --height 32 --sample 1 --threads 2 -q " +
                                     "--budget-steps " + std::to_string(steps) + " -o " + out);
  EXPECT_EQ(r.exitCode, 0) << r.err;
  return files[steps] = out;
}

TEST(CliOptions, DatasetBudgetStepsGivesNBudgetsOfSamplesPerView) {
  const uint64_t covered[2] = {coveredPixels("'procedural:layers?k=4'"),
                               coveredPixels("'procedural:spheres?count=3'")};
  ASSERT_GT(covered[0], 0u);
  ASSERT_GT(covered[1], 0u);
  for (const int steps : {2, 3}) {
    auto data = mfr::learn::readDataset(dataset(steps));
    ASSERT_TRUE(data.ok()) << data.error().message;
    ASSERT_EQ(data->scenes.size(), 2u);
    std::map<std::pair<uint32_t, uint32_t>, uint64_t> perSceneAndStep;
    for (const mfr::learn::DatasetSample& s : data->samples) {
      ASSERT_LT(s.budgetStep, static_cast<uint32_t>(steps));
      EXPECT_EQ(s.view, 0u);
      EXPECT_GE(s.target, 0.0f);
      EXPECT_LE(s.target, 1.0f);
      ++perSceneAndStep[std::make_pair(s.scene, s.budgetStep)];
    }
    // --sample 1: every covered pixel at every one of the N budgets
    EXPECT_EQ(perSceneAndStep.size(), static_cast<size_t>(2 * steps));
    for (uint32_t scene = 0; scene < 2; ++scene)
      for (uint32_t step = 0; step < static_cast<uint32_t>(steps); ++step)
        EXPECT_EQ(perSceneAndStep[std::make_pair(scene, step)], covered[scene])
            << "steps " << steps << " scene " << scene << " step " << step;
    EXPECT_EQ(data->samples.size(), static_cast<size_t>(steps) * (covered[0] + covered[1]));
    const json meta = json::parse(data->metadata, nullptr, false);
    EXPECT_EQ(meta["budget_steps"].get<int>(), steps);
  }
}

// The network's parameters (not the file bytes, whose metadata records the options).
std::vector<float> parameters(const std::string& model) {
  auto m = mfr::learn::readModel(model);
  EXPECT_TRUE(m.ok()) << model;
  std::vector<float> p;
  if (!m.ok()) return p;
  for (size_t l = 0; l < m->net.weights.size(); ++l) {
    p.insert(p.end(), m->net.weights[l].data(),
             m->net.weights[l].data() + m->net.weights[l].size());
    p.insert(p.end(), m->net.biases[l].data(), m->net.biases[l].data() + m->net.biases[l].size());
  }
  return p;
}

struct Trained {
  std::string model, log, curve;
};

Trained train(const std::string& name, const std::string& options) {
  Trained t{path(name + ".mfrnn"), path(name + "_log.csv"), path(name + "_curve.png")};
  const mfr::test::CliRun r =
      runCli("train " + dataset(3) + " --epochs 4 --learning-rate 0.05 --seed 2 -q " + options +
             " --log " + t.log + " --loss-curve " + t.curve + " -o " + t.model);
  EXPECT_EQ(r.exitCode, 0) << r.err;
  return t;
}

TEST(CliOptions, TrainWritesTheLogAndLossCurveWhereToldAndHonoursL1L2AndBatch) {
  const Trained a = train("a", "--batch 32 --l1 0 --l2 0");
  // the log: a header and one row per epoch, epochs 1..4, finite losses
  std::ifstream log(a.log);
  std::string line;
  ASSERT_TRUE(std::getline(log, line)) << a.log;
  EXPECT_EQ(line, "epoch,train_mse,validation_mse,seconds");
  int rows = 0;
  while (std::getline(log, line)) {
    ++rows;
    std::istringstream fields(line);
    std::string epoch, trainMse, validMse;
    std::getline(fields, epoch, ',');
    std::getline(fields, trainMse, ',');
    std::getline(fields, validMse, ',');
    EXPECT_EQ(epoch, std::to_string(rows));
    EXPECT_TRUE(std::isfinite(std::stod(trainMse))) << line;
    EXPECT_TRUE(std::isfinite(std::stod(validMse))) << line << ": two scenes, one held out";
  }
  EXPECT_EQ(rows, 4);
  // the loss curve: a PNG of the plot's size (PlotOptions: 800 x 500)
  const mfr::Image8 curve = readImage(a.curve);
  EXPECT_EQ(curve.width, 800);
  EXPECT_EQ(curve.height, 500);
  EXPECT_FALSE(fs::exists(a.model + ".log.csv")) << "--log replaces the default name";
  EXPECT_FALSE(fs::exists(a.model + ".loss.png")) << "--loss-curve replaces the default name";
  // the options reach the trainer: recorded in the model ...
  auto model = mfr::learn::readModel(a.model);
  ASSERT_TRUE(model.ok()) << model.error().message;
  const json meta = json::parse(model->metadata, nullptr, false);
  EXPECT_EQ(meta["training"]["batch"].get<int>(), 32);
  EXPECT_EQ(meta["training"]["epochs"].get<int>(), 4);
  EXPECT_EQ(meta["training"]["l1_first_hidden"].get<double>(), 0.0);
  EXPECT_EQ(meta["training"]["l2_second_hidden"].get<double>(), 0.0);
  // ... and change the weights; the same options give the same weights
  const std::vector<float> pa = parameters(a.model);
  ASSERT_FALSE(pa.empty());
  const Trained again = train("a2", "--batch 32 --l1 0 --l2 0");
  EXPECT_EQ(readBytes(again.model), readBytes(a.model)) << "same options: same model bytes";
  const Trained l1 = train("l1", "--batch 32 --l1 0.01 --l2 0");
  EXPECT_NE(readBytes(l1.model), readBytes(a.model)) << "--l1";
  EXPECT_NE(parameters(l1.model), pa) << "--l1 changes the weights, not only the metadata";
  EXPECT_NE(parameters(train("l2", "--batch 32 --l1 0 --l2 0.1").model), pa) << "--l2";
  EXPECT_NE(parameters(train("batch", "--batch 64 --l1 0 --l2 0").model), pa) << "--batch";
}

TEST(CliOptions, RenderWithATrainedModelDiffersFromTheBuiltInAndIsReproducible) {
  const Trained t = train("render_model", "--batch 32 --l1 0 --l2 0");
  const std::string common =
      "render 'procedural:hairball?strands=300' --width 48 --height 48 --threads 2 -m dkb "
      "-M 120KB --composite hybrid -q ";
  const std::string first = path("model_first.png"), second = path("model_second.png"),
                    builtin = path("model_builtin.png");
  const std::string kFirst = path("model_first_k.png"), kBuiltin = path("model_builtin_k.png");
  runOk(common + "--model " + t.model + " -o " + first + " --k-map " + kFirst);
  runOk(common + "--model " + t.model + " -o " + second);
  runOk(common + "-o " + builtin + " --k-map " + kBuiltin);
  const mfr::Image8 a = readImage(first), b = readImage(second), c = readImage(builtin);
  ASSERT_EQ(a.width, 48);
  EXPECT_EQ(differingPixels(a, b), 0) << "the same model: the same image";
  EXPECT_GT(differingPixels(a, c), 0) << "a different model: a different image";
  EXPECT_NE(readBytes(kFirst), readBytes(kBuiltin)) << "and a different allocation";
}

}  // namespace

// An option given with an empty value is given: `--composite ""` names no rule, `--model ""` no
// file; each is one error line, not the preset's default.
TEST(CliOptions, EmptyCompositeAndModelAreErrors) {
  const std::string base =
      "render procedural:bottles --width 16 --height 16 -q -o " + path("e.png");
  for (const auto& [args, message] :
       {std::pair<std::string, std::string>{" --method fkb --k 2 --composite ''",
                                            "mfr: error: --composite: "},
        {" --method dkb --budget 1MB --model ''", "mfr: error: --model: empty path"}}) {
    const mfr::test::CliRun r = runCli(base + args);
    EXPECT_EQ(r.exitCode, 1) << args;
    EXPECT_EQ(r.err.rfind(message, 0), 0u) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  }
}
