// Image outputs are written in the format their name says: `render -o` takes .png (sRGB) or .pfm
// (Portable Float Map: the linear floats), the maps and the other commands' images .png only, and
// any other extension is refused before any work, in one line naming the option, the path and the
// accepted extensions (before: `-o x.exr` wrote PNG bytes under that name).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "cli_runner.hpp"
#include "mfr/core/color.hpp"
#include "mfr/core/image.hpp"

namespace mfr {
namespace {

namespace fs = std::filesystem;

fs::path tempDir() {
  static const fs::path dir = test::processTempDir("mfr_image_outputs");
  return dir;
}

test::CliRun runCli(const std::string& args) {
  return test::runCli(args, tempDir());
}

std::string readBytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

float floatAt(const std::string& bytes, size_t offset) {  // little-endian float32
  uint32_t word = 0;
  for (int i = 3; i >= 0; --i)
    word = word << 8 | static_cast<uint8_t>(bytes.at(offset + static_cast<size_t>(i)));
  float f;
  std::memcpy(&f, &word, 4);
  return f;
}

// one "mfr: error: ..." line containing `needle`, exit 1, and none of `never` written
void expectRefused(const std::string& args, const std::string& needle,
                   const std::vector<fs::path>& never) {
  for (const fs::path& p : never) fs::remove(p);
  const test::CliRun r = runCli(args);
  EXPECT_FALSE(r.signaled) << args;
  EXPECT_EQ(r.exitCode, 1) << args << "\n" << r.err;
  EXPECT_EQ(r.err.rfind("mfr: error: ", 0), 0u) << args << "\n" << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << "\n" << r.err;
  EXPECT_NE(r.err.find(needle), std::string::npos) << args << "\n" << r.err;
  for (const fs::path& p : never) EXPECT_FALSE(fs::exists(p)) << args << ": wrote " << p;
}

TEST(ImageOutputs, PfmBytesAreTheLinearFloatsBottomRowFirst) {
  ImageRGB image(3, 2);
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 3; ++x) image.at(x, y) = {x + 10.0f * y, -0.5f * x, 1e6f + y};
  const fs::path path = tempDir() / "small.pfm";
  ASSERT_TRUE(writePfm(path.string(), image).ok());
  const std::string bytes = readBytes(path);
  const std::string header = "PF\n3 2\n-1.0\n";
  ASSERT_EQ(bytes.size(), header.size() + 3 * 2 * 12);
  EXPECT_EQ(bytes.substr(0, header.size()), header);
  // file row 0 is the image's bottom row (y = 1)
  for (int fileRow = 0; fileRow < 2; ++fileRow)
    for (int x = 0; x < 3; ++x)
      for (int c = 0; c < 3; ++c) {
        const size_t offset = header.size() + static_cast<size_t>((fileRow * 3 + x) * 3 + c) * 4;
        EXPECT_EQ(floatAt(bytes, offset), image.at(x, 1 - fileRow)[c]) << fileRow << " " << x;
      }
  EXPECT_FALSE(writePfm((tempDir() / "empty.pfm").string(), ImageRGB()).ok());
}

TEST(ImageOutputs, FormatFromTheExtensionOrOneLineNamingOptionPathAndAccepted) {
  const auto both = {OutputImageFormat::Png, OutputImageFormat::Pfm};
  EXPECT_EQ(imageOutputFormat("--out", "a/b.png", both).value(), OutputImageFormat::Png);
  EXPECT_EQ(imageOutputFormat("--out", "b.PFM", both).value(), OutputImageFormat::Pfm);
  EXPECT_EQ(imageOutputFormat("--out", "b.Png", {OutputImageFormat::Png}).value(),
            OutputImageFormat::Png);
  // a special file has no name to go by: the first accepted format
  EXPECT_EQ(imageOutputFormat("--out", "/dev/null", both).value(), OutputImageFormat::Png);
  const auto refused = [&](const std::string& path, std::initializer_list<OutputImageFormat> ok) {
    auto r = imageOutputFormat("--k-map", path, ok);
    return r ? std::string("accepted") : r.error().message;
  };
  EXPECT_EQ(refused("x.exr", both),
            "--k-map 'x.exr': unsupported image extension '.exr' (accepted: .png, .pfm)");
  EXPECT_EQ(refused("dir.png/x.jpg", {OutputImageFormat::Png}),
            "--k-map 'dir.png/x.jpg': unsupported image extension '.jpg' (accepted: .png)");
  EXPECT_EQ(refused("x.pfm", {OutputImageFormat::Png}),
            "--k-map 'x.pfm': unsupported image extension '.pfm' (accepted: .png)");
  EXPECT_EQ(refused("image", both), "--k-map 'image': no image extension (accepted: .png, .pfm)");
  EXPECT_EQ(refused("x.png.bak", both),
            "--k-map 'x.png.bak': unsupported image extension '.bak' (accepted: .png, .pfm)");
}

const std::string kRender = "render procedural:layers --width 40 --height 24 -q ";

TEST(ImageOutputs, RenderRefusesOtherExtensionsBeforeAnyWork) {
  const fs::path d = tempDir();
  const fs::path stats = d / "stats.json";
  for (const char* name : {"x.exr", "x.jpg", "x.tiff", "x", "x.png.tmp"}) {
    const fs::path out = d / name;
    const std::string ext = fs::path(name).extension().string();
    const std::string what =
        ext.empty() ? "no image extension" : "unsupported image extension '" + ext + "'";
    expectRefused(kRender + "-o " + out.string() + " --stats-json " + stats.string(),
                  "--out '" + out.string() + "': " + what + " (accepted: .png, .pfm)",
                  {out, stats});
  }
  // checked before the scene is loaded: a scene that does not exist is not reached
  expectRefused("render " + (d / "missing.gltf").string() + " -q -o " + (d / "y.exr").string(),
                "--out '" + (d / "y.exr").string() + "': unsupported image extension '.exr'",
                {d / "y.exr"});
  // the maps: PNG only
  const std::pair<std::string, std::string> maps[] = {{"--depth-complexity", "d.exr"},
                                                      {"--k-map", "k.jpg"},
                                                      {"--overflow-map", "o.pfm"},
                                                      {"--importance-map", "i.bmp"}};
  for (const auto& [option, name] : maps) {
    const fs::path map = d / name, out = d / "fine.png";
    expectRefused(kRender + "-m vkb -M 64KB --samples 2 -o " + out.string() + " " + option + " " +
                      map.string(),
                  option + " '" + map.string() + "': unsupported image extension '" +
                      map.extension().string() + "' (accepted: .png)",
                  {map, out});
  }
}

TEST(ImageOutputs, OtherCommandsImagesArePngOnly) {
  const fs::path d = tempDir();
  const std::string missing = (d / "missing.png").string();
  expectRefused("metrics " + missing + " " + missing + " --flip-map " + (d / "f.jpg").string(),
                "--flip-map '" + (d / "f.jpg").string() +
                    "': unsupported image extension '.jpg' (accepted: .png)",
                {d / "f.jpg"});
  expectRefused("metrics " + missing + " " + missing + " --error-map " + (d / "e").string(),
                "--error-map '" + (d / "e").string() + "': no image extension (accepted: .png)",
                {d / "e"});
  expectRefused("train " + (d / "missing.mfrds").string() + " -q -o " + (d / "m.mfrnn").string() +
                    " --loss-curve " + (d / "loss.svg").string(),
                "--loss-curve '" + (d / "loss.svg").string() + "': unsupported image extension",
                {d / "loss.svg", d / "m.mfrnn"});
}

TEST(ImageOutputs, RenderPfmHoldsTheLinearImageThePngEncodes) {
  const fs::path d = tempDir();
  const fs::path png = d / "same.png", pfm = d / "same.PFM";
  // an oblique camera: the image is not symmetric top to bottom, so a flipped PFM shows
  const std::string camera = " --camera 0.7,1.9,3.1,0,0.2,0 --alpha 0.6 -m fkb -M 64KB";
  ASSERT_EQ(runCli(kRender + camera + " -o " + png.string()).exitCode, 0);
  const test::CliRun r = runCli(kRender + camera + " -o " + pfm.string());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const Image8 encoded = readPng(png.string()).value();
  const std::string bytes = readBytes(pfm);
  const std::string header = "PF\n40 24\n-1.0\n";
  ASSERT_EQ(bytes.size(), header.size() + 40 * 24 * 12);
  ASSERT_EQ(bytes.substr(0, header.size()), header);
  bool asymmetric = false;
  for (int y = 0; y < 24; ++y)
    for (int x = 0; x < 40; ++x)
      for (int c = 0; c < 3; ++c) {
        const size_t fileRow = static_cast<size_t>(23 - y);  // bottom row first
        const float linear = floatAt(bytes, header.size() + ((fileRow * 40 + x) * 3 + c) * 4);
        const uint8_t code = encoded.rgba[(static_cast<size_t>(y) * 40 + x) * 4 + c];
        EXPECT_EQ(encodeSrgb8(linear), code) << x << "," << y << " " << c;
        asymmetric |= code != encoded.rgba[((23 - static_cast<size_t>(y)) * 40 + x) * 4 + c];
      }
  EXPECT_TRUE(asymmetric) << "the test image must tell top from bottom";
  // a PNG is a PNG: its signature, under a .png name whatever the case
  const fs::path upper = d / "upper.PNG";
  ASSERT_EQ(runCli(kRender + "-o " + upper.string()).exitCode, 0);
  EXPECT_EQ(readBytes(upper).substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
}

}  // namespace
}  // namespace mfr
