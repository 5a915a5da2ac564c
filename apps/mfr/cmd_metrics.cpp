// mfr metrics: a test image against a reference, like the FLIP tool but with MSE and PSNR too.
// PSNR of identical images is +infinity: printed as "inf", written as null in JSON.
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "common.hpp"
#include "mfr/core/image.hpp"
#include "mfr/core/json_limits.hpp"
#include "mfr/core/memory_limit.hpp"
#include "mfr/core/quote.hpp"
#include "mfr/core/units.hpp"
#include "mfr/method/make_method.hpp"
#include "mfr/metrics/flip.hpp"
#include "mfr/metrics/image_metrics.hpp"

namespace mfr::cli {
namespace {

struct MetricsArgs {
  std::string reference;
  std::string test;
  std::string flipMap;
  std::string errorMap;
  double pixelsPerDegree = kFlipDefaultPixelsPerDegree;
  std::string memoryLimit;  // --memory-limit (empty: defaultMemoryLimit())
  bool json = false;
  bool quiet = false;
};

nlohmann::json finiteOrNull(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
}

std::string psnrText(double psnr) {
  if (!std::isfinite(psnr)) return "inf";
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.2f dB", psnr);
  return buffer;
}

std::string sizeText(const Image8& image) {
  std::string s = std::to_string(image.width);
  s += 'x';
  s += std::to_string(image.height);
  return s;
}

/// What `mfr metrics` holds at its peak for two width x height images: both decoded (RGBA8),
/// stb_image's buffers while the second decodes (its inflated rows and its output), FLIP's planes
/// and error map, a copy of the map for the percentiles and the maps it writes.
uint64_t metricsBytes(int width, int height) {
  const uint64_t pixels = static_cast<uint64_t>(width) * static_cast<uint64_t>(height);
  return saturatingAdd(flipWorkingBytes(width, height), saturatingMul(pixels, 4 + 4 + 8 + 4 + 8));
}

int run(const MetricsArgs& a) {
  if (a.reference.empty() || a.test.empty())
    return fail("metrics: expected two images, REFERENCE.png TEST.png");
  if (auto ppd = checkFlipPixelsPerDegree(a.pixelsPerDegree); !ppd)
    return fail(ppd.error().message);
  uint64_t limit = defaultMemoryLimit();
  if (!a.memoryLimit.empty()) {
    auto parsed = parseMemoryLimitOption(a.memoryLimit);
    if (!parsed) return fail(parsed.error().message);
    limit = parsed.value();
  }
  if (auto distinct = checkDistinctOutputs({{"--flip-map", a.flipMap}, {"--error-map", a.errorMap}},
                                           {{"reference", a.reference}, {"test image", a.test}});
      !distinct)
    return fail(distinct.error().message);
  for (const auto& [option, path] :
       {std::pair{"--flip-map", &a.flipMap}, std::pair{"--error-map", &a.errorMap}})
    if (!path->empty())
      if (auto format = imageOutputFormat(option, *path, {OutputImageFormat::Png}); !format)
        return fail(format.error().message);
  // from each header, before its pixels are decoded (images of one size: the first check counts
  // both)
  const auto preflight = [limit](const std::string& path) {
    return [limit, path](int width, int height) {
      return checkMemory(metricsBytes(width, height), limit,
                         echoPath(path) + ": " + std::to_string(width) + " x " +
                             std::to_string(height) + " pixels: the two images and FLIP's buffers");
    };
  };
  auto reference = readPng(a.reference, preflight(a.reference));
  if (!reference) return fail(reference.error().message);
  auto test = readPng(a.test, preflight(a.test));
  if (!test) return fail(test.error().message);
  if (reference->width != test->width || reference->height != test->height) {
    std::string message = echoPath(a.reference);
    message += " is ";
    message += sizeText(*reference);
    message += " but ";
    message += echoPath(a.test);
    message += " is ";
    message += sizeText(*test);
    message += ": images must have the same size";
    return fail(message);
  }
  auto stats = compareImages(*reference, *test);
  if (!stats) return fail(stats.error().message);
  auto flip = computeFlip(*reference, *test, a.pixelsPerDegree);
  if (!flip) return fail(flip.error().message);

  double errorScale = 0.0;
  if (!a.flipMap.empty()) {
    auto written = writePng(a.flipMap, flipErrorImage(*flip));
    if (!written) return fail(written.error().message);
  }
  if (!a.errorMap.empty()) {
    auto map = squaredErrorMap(*reference, *test, MetricSpace::Srgb);
    if (!map) return fail(map.error().message);
    errorScale = map->maxValue();
    auto written = writePng(a.errorMap, errorMapImage(*map));
    if (!written) return fail(written.error().message);
  }

  const double median = flipPercentile(*flip, 0.5), p95 = flipPercentile(*flip, 0.95),
               p99 = flipPercentile(*flip, 0.99), maxFlip = flipPercentile(*flip, 1.0);
  if (a.json) {
    nlohmann::json j = {{"reference", a.reference},
                        {"test", a.test},
                        {"width", stats->width},
                        {"height", stats->height},
                        {"mse_linear", stats->mseLinear},
                        {"mse_srgb", stats->mseSrgb},
                        {"psnr_linear", finiteOrNull(stats->psnrLinear)},
                        {"psnr_srgb", finiteOrNull(stats->psnrSrgb)},
                        {"flip_mean", flip->mean},
                        {"flip_median", median},
                        {"flip_p95", p95},
                        {"flip_p99", p99},
                        {"flip_max", maxFlip},
                        {"pixels_per_degree", a.pixelsPerDegree}};
    if (!a.flipMap.empty()) j["flip_map"] = a.flipMap;
    if (!a.errorMap.empty()) {
      j["error_map"] = a.errorMap;
      j["error_map_scale"] = errorScale;
    }
    std::printf("%s\n", jsonText(j).c_str());
    return 0;
  }
  if (a.quiet) return 0;
  std::printf("reference  %s\n", a.reference.c_str());
  std::printf("test       %s (%dx%d)\n", a.test.c_str(), stats->width, stats->height);
  std::printf("MSE        linear %.6g   sRGB %.6g\n", stats->mseLinear, stats->mseSrgb);
  std::printf("PSNR       linear %s   sRGB %s\n", psnrText(stats->psnrLinear).c_str(),
              psnrText(stats->psnrSrgb).c_str());
  std::printf("FLIP       mean %.6f   median %.6f   p95 %.6f   p99 %.6f   max %.6f (%.2f ppd)\n",
              flip->mean, median, p95, p99, maxFlip, a.pixelsPerDegree);
  if (!a.flipMap.empty()) std::printf("flip map   %s (magma, 0..1)\n", a.flipMap.c_str());
  if (!a.errorMap.empty())
    std::printf("error map  %s (magma, squared sRGB error 0..%.6g)\n", a.errorMap.c_str(),
                errorScale);
  return 0;
}

}  // namespace

Runner addMetricsCommand(CLI::App& app) {
  auto args = std::make_shared<MetricsArgs>();
  CLI::App* cmd = app.add_subcommand(
      "metrics", "Compare TEST.png against REFERENCE.png: MSE and PSNR (linear and sRGB), FLIP");
  cmd->add_option("reference", args->reference, "Reference image (PNG, sRGB)");
  cmd->add_option("test", args->test, "Test image (PNG, sRGB), same size as the reference");
  cmd->add_option("--flip-map", args->flipMap, "Write the FLIP error map (magma) as PNG");
  cmd->add_option("--error-map", args->errorMap,
                  "Write the per-pixel squared sRGB error (magma, scaled to its maximum) as PNG");
  cmd->add_option("--ppd", args->pixelsPerDegree,
                  "FLIP pixels per degree (default 67.02: 0.7 m from a 0.7 m wide 4K display)");
  cmd->add_option("--memory-limit", args->memoryLimit,
                  "Refuse images whose decoding and FLIP need more than this, e.g. 8GB (default: " +
                      std::to_string(static_cast<int>(kDefaultMemoryShare * 100)) +
                      "% of the physical memory, of the address-space limit (ulimit -v) or of "
                      "the cgroup's memory limit, whichever is least: " +
                      formatBytes(defaultMemoryLimit()) + ")");
  cmd->add_flag("--json", args->json, "Print machine-readable JSON on stdout");
  cmd->add_flag("--quiet,-q", args->quiet, "Print nothing (errors still go to stderr)");
  return [args] { return run(*args); };
}

}  // namespace mfr::cli
