// PNG input of `mfr metrics` (readPng: signature check, stb_image), then what metrics does with
// the image: MSE / PSNR (up to 4096 pixels) and FLIP (up to 256) against itself (zero error)
// and against its inverse.
#include <cstddef>
#include <cstdint>

#include "fuzz_util.hpp"
#include "mfr/core/image.hpp"
#include "mfr/metrics/flip.hpp"
#include "mfr/metrics/image_metrics.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = mfr::fuzz::workDir().write("image.png", data, size);
  auto image = mfr::readPng(path);
  if (!image) {
    mfr::fuzz::checkError(image.error(), path);
    return 0;
  }
  FUZZ_CHECK(image->width > 0 && image->height > 0, "empty image read");
  FUZZ_CHECK(image->rgba.size() == static_cast<size_t>(image->width) * image->height * 4,
             "pixel buffer size");
  // the metrics on small images only: FLIP's filters make large ones slow, and add no new paths
  const size_t pixels = static_cast<size_t>(image->width) * image->height;
  if (pixels > 4096) return 0;
  mfr::Image8 inverse = image.value();
  for (uint8_t& v : inverse.rgba) v = static_cast<uint8_t>(255 - v);
  for (const mfr::Image8* test : {&image.value(), &inverse}) {
    const bool itself = test == &image.value();
    auto stats = mfr::compareImages(image.value(), *test);
    if (!stats) mfr::fuzz::checkError(stats.error());
    if (itself)
      FUZZ_CHECK(stats && stats->mseLinear == 0.0 && stats->mseSrgb == 0.0, "MSE of itself");
    if (pixels > 256) continue;
    auto flip = mfr::computeFlip(image.value(), *test, mfr::kFlipDefaultPixelsPerDegree);
    if (!flip) mfr::fuzz::checkError(flip.error());
    if (flip)
      for (float e : flip->errorMap)
        FUZZ_CHECK(e >= 0.0f && e <= 1.0f, "FLIP error outside [0, 1]");
    if (itself) FUZZ_CHECK(flip && flip->mean == 0.0, "FLIP of itself");
  }
  return 0;
}
