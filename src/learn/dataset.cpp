// The deep k-buffer's training set: generation from a rendered view (features + optimal targets,
// DHOIT sec. 3.1.1-3.1.2) and the .mfrds file format (dataset.hpp).
#include "mfr/learn/dataset.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string_view>

#include <tbb/task_arena.h>
#include <nlohmann/json.hpp>

#include "mfr/core/atomic_file.hpp"
#include "mfr/core/file_access.hpp"
#include "mfr/core/json_limits.hpp"
#include "mfr/core/quote.hpp"
#include "mfr/cpu/deep_importance.hpp"
#include "mfr/cpu/optimal_oracle.hpp"
#include "mfr/learn/model_file.hpp"
#include "mfr/method/budget_spec.hpp"
#include "mfr/method/dfaoit.hpp"
#include "mfr/method/optimal_allocation.hpp"

namespace mfr::learn {
namespace {

static_assert(std::endian::native == std::endian::little, "the file formats are little-endian");

constexpr char kMagic[8] = {'M', 'F', 'R', 'D', 'S', 0, 0, 0};
constexpr uint32_t kMaxScenes = 65536, kMaxName = 4096, kMaxMetadata = 1u << 20;
size_t sampleBytes(uint32_t targets) {
  return 4 * 4 + 4 * kDkbFeatureCount + 4 * size_t{targets};
}

uint64_t mix(uint64_t x) {  // SplitMix64 finaliser
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

// Uniform in [0, 1) from the sample's coordinates: independent of threads and of other samples.
double sampleUniform(uint64_t seed, uint32_t scene, uint32_t view, uint32_t step, uint32_t pixel) {
  uint64_t h = mix(seed);
  h = mix(h ^ scene);
  h = mix(h ^ (static_cast<uint64_t>(view) << 32 | step));
  h = mix(h ^ pixel);
  return static_cast<double>(h >> 11) * 0x1.0p-53;
}

template <class T>
void put(std::string& out, T v) {
  out.append(reinterpret_cast<const char*>(&v), sizeof(T));
}

class Reader {
 public:
  Reader(const std::string& bytes, const std::string& path) : bytes_(bytes), path_(path) {}
  template <class T>
  bool get(T& v) {
    if (bytes_.size() - pos_ < sizeof(T)) return false;
    std::memcpy(&v, bytes_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return true;
  }
  bool getString(std::string& s, size_t n) {
    if (bytes_.size() - pos_ < n) return false;
    s.assign(bytes_.data() + pos_, n);
    pos_ += n;
    return true;
  }
  size_t remaining() const { return bytes_.size() - pos_; }
  Error error(const std::string& what) const {
    return makeError("dataset " + echoPath(path_) + ": " + what + " (at byte " +
                     std::to_string(pos_) + ")");
  }

 private:
  const std::string& bytes_;
  const std::string& path_;
  size_t pos_ = 0;
};

/// The problem with scene name `index`, or "": 1..kMaxName bytes of UTF-8 (the format's rule).
std::string sceneNameProblem(const std::string& name, size_t index) {
  const std::string which = "scene " + std::to_string(index) + "'s name";
  if (name.empty() || name.size() > kMaxName)
    return which + " is " + std::to_string(name.size()) + " bytes long (1 to " +
           std::to_string(kMaxName) + " allowed)";
  if (const size_t bad = invalidUtf8At(name); bad != std::string_view::npos)
    return which + " is not valid UTF-8 (at byte " + std::to_string(bad) + " of " +
           std::to_string(name.size()) + ")";
  return "";
}

/// A float for a message.
std::string number(float v) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", static_cast<double>(v));
  return text;
}

}  // namespace

std::optional<SampleProblem> datasetSampleProblem(const DatasetSample& s, uint32_t targetCount,
                                                  size_t sceneCount) {
  if (s.scene >= sceneCount)
    return SampleProblem{"scene", "scene index " + std::to_string(s.scene) +
                                      " is not below the scene count " +
                                      std::to_string(sceneCount)};
  for (size_t i = 0; i < s.features.size(); ++i)
    if (!std::isfinite(s.features[i]))
      return SampleProblem{"features", "feature " + std::to_string(i) + " is " +
                                           number(s.features[i]) + ", not a finite number"};
  const auto outside = [](std::string what, float t) -> std::optional<SampleProblem> {
    if (std::isfinite(t) && t >= 0.0f && t <= 1.0f) return std::nullopt;
    return SampleProblem{"targets", what + " is " + number(t) + ", outside [0, 1]"};
  };
  // the targets the file holds (Dataset::targetCount)
  if (targetCount == kDfaoitTargetCount) {
    for (size_t i = 0; i < s.colour.size(); ++i)
      if (auto p = outside("colour target " + std::to_string(i), s.colour[i])) return p;
  } else if (targetCount == 1) {
    return outside("target", s.target);
  } else {
    for (size_t i = 0; i < s.curve.size() && i < targetCount; ++i)
      if (auto p = outside("curve target " + std::to_string(i), s.curve[i])) return p;
  }
  return std::nullopt;
}

uint64_t fnv1a64(std::string_view bytes) {
  uint64_t h = 0xcbf29ce484222325ull;
  for (const char c : bytes) h = (h ^ static_cast<uint8_t>(c)) * 0x100000001b3ull;
  return h;
}

std::string hashHex(uint64_t hash) {
  std::string s(16, '0');
  for (int i = 15; i >= 0; --i, hash >>= 4) s[i] = "0123456789abcdef"[hash & 15];
  return s;
}

uint64_t budgetStepSlots(uint64_t coveredPixels, uint64_t fragments, int step, int steps) {
  if (steps <= 1) return fragments;
  const double t = static_cast<double>(step) / (steps - 1);
  return coveredPixels +
         static_cast<uint64_t>(std::llround(t * static_cast<double>(fragments - coveredPixels)));
}

Result<std::vector<DatasetSample>> sampleView(const RasterFrame& frame, uint32_t scene,
                                              uint32_t view, const ViewSamplingOptions& options) {
  // curve targets start at the rule's first k (0, the tail alone, under hybrid compositing); the
  // importance targets always come from the curves from k = 1 (the paper's optimal k-buffer)
  const uint32_t firstK = options.curveTargets ? curveFirstK(options.compositing) : 1;
  auto oracle = frameErrorCurves(frame, options.background, options.compositing,
                                 options.memoryLimitBytes, firstK);
  if (!oracle) return oracle.error();
  std::vector<CurveTargets> curves;
  if (options.curveTargets) {
    const double scale = firstK == 0 ? 1.0 : curveScale(oracle->curves);
    curves.resize(oracle->curves.size());
    for (size_t p = 0; p < curves.size(); ++p)
      if (!oracle->curves[p].empty()) curves[p] = curveTargets(oracle->curves[p], scale, firstK);
    if (firstK == 0)  // err(k) for k >= 1 are the same values as curves from k = 1
      for (std::vector<double>& c : oracle->curves)
        if (!c.empty()) c.erase(c.begin());
  }
  const std::vector<FeatureAccumulator> pixels = accumulateFeatures(frame);
  const ImageFeatureStats image = imageFeatureStats(pixels);
  std::vector<DatasetSample> samples;
  if (image.coveredPixels == 0) return samples;
  const bool relative = !options.budgetPercents.empty();
  MethodDesc oracleMethod;  // what a share must serve: one node per covered pixel
  oracleMethod.allocation = AllocationPolicy::Optimal;
  const int steps =
      relative ? static_cast<int>(options.budgetPercents.size()) : options.budgetSteps;
  FrameCounts counts;
  counts.pixels = pixels.size();
  counts.coveredPixels = image.coveredPixels;
  counts.fragments = image.fragments;
  for (int step = 0; step < steps; ++step) {
    uint64_t slots = budgetStepSlots(image.coveredPixels, image.fragments, step, steps);
    if (relative) {
      const BudgetSpec share = BudgetSpec::relative(options.budgetPercents[step]);
      slots = relativeNodeBytes(share.percent, counts) / kNodeBytes;
      if (slots < image.coveredPixels)
        return makeError(
            "budget " + share.label +
            ": too small for one node per covered pixel (needs at least " +
            BudgetSpec::relative(smallestWorkingPercent(oracleMethod, MemoryModel{}, counts))
                .label +
            " of the A-buffer's " + std::to_string(image.fragments) + " nodes)");
      slots = std::min(slots, image.fragments);
    }
    std::vector<uint32_t> k;  // on the frame's workers (the same k on any number)
    tbb::task_arena(frame.arenaThreads()).execute([&] {
      k = allocateOptimalHull(oracle->curves, slots);
    });
    const uint32_t kMax = *std::max_element(k.begin(), k.end());
    for (uint32_t p = 0; p < pixels.size(); ++p) {
      if (pixels[p].n == 0) continue;
      const uint32_t s = static_cast<uint32_t>(step);
      if (sampleUniform(options.seed, scene, view, s, p) >= options.sampleFraction) continue;
      DatasetSample sample;
      sample.scene = scene;
      sample.view = view;
      sample.budgetStep = s;
      sample.pixel = p;
      sample.features = pixelFeatures(pixels[p], image, slots);
      sample.target = static_cast<float>(k[p]) / static_cast<float>(kMax);
      if (options.curveTargets) {
        sample.curve = curves[p];
        sample.curveFeatures = firstK == 0 ? curvePixelFeatures(pixels[p]) : sample.features;
      }
      samples.push_back(sample);
    }
  }
  return samples;
}

std::vector<DatasetSample> sampleDfaoitView(const RasterFrame& frame, uint32_t scene, uint32_t view,
                                            const ViewSamplingOptions& options) {
  const size_t pixels = frame.pixelCount();
  std::vector<DfaoitPixel> sums(pixels);
  std::vector<std::vector<FragmentNode>> nodes(pixels);
  // tile-owned: a pixel's fragments in primitive order on one worker, as the CPU engine's capture
  frame.forEachTile([&](int tile) {
    frame.rasterizeTile<ShadeMode::Full>(tile, EmitAll{[&](const Fragment& f) {
                                           sums[f.pixel].add(f.depth, f.rgba);
                                           nodes[f.pixel].push_back(makeNode(f.depth, f.rgba));
                                         }});
  });
  std::vector<DatasetSample> samples;
  for (uint32_t p = 0; p < pixels; ++p) {
    if (sums[p].n < 3) continue;  // (one or two fragments: the resolve needs no network)
    if (sampleUniform(options.seed, scene, view, 0, p) >= options.sampleFraction) continue;
    std::vector<FragmentNode>& px = nodes[p];
    std::sort(px.begin(), px.end());  // the A-buffer's order
    float r = 0.0f, g = 0.0f, b = 0.0f, T = 1.0f;
    for (const FragmentNode node : px) {
      const glm::vec4 c = unpackFragmentColor(nodeColor(node));
      method_math::overStep(r, g, b, T, c.a, c.r, c.g, c.b);
    }
    // y': the colour behind the nearest fragment (the A-buffer's first) over its coverage share
    const glm::vec4 near = unpackFragmentColor(sums[p].nearColour);
    const float share = (1.0f - near.a) - T;
    if (!(share > 1e-4f)) continue;  // (what lies behind is invisible: y' does not matter)
    DatasetSample sample;
    sample.scene = scene;
    sample.view = view;
    sample.pixel = p;
    const DfaoitInputs x = sums[p].features();
    std::copy(x.begin(), x.end(), sample.features.begin());
    const float rest[3] = {r - near.a * near.r, g - near.a * near.g, b - near.a * near.b};
    for (int i = 0; i < 3; ++i)
      sample.colour[static_cast<size_t>(i)] = std::clamp(rest[i] / share, 0.0f, 1.0f);
    samples.push_back(sample);
  }
  return samples;
}

Result<void> writeDataset(const std::string& path, const Dataset& data) {
  // what readDataset refuses is never written
  const auto refuse = [&](const std::string& problem) {
    return makeError("dataset " + echoPath(path) + ": cannot write it: " + problem);
  };
  if (data.targetCount != 1 && data.targetCount != kCurveOutputs &&
      data.targetCount != kDfaoitTargetCount)
    return refuse(std::to_string(data.targetCount) + " targets per sample, not 1, " +
                  std::to_string(kDfaoitTargetCount) + " or " + std::to_string(kCurveOutputs));
  if (data.scenes.empty() || data.scenes.size() > kMaxScenes)
    return refuse(std::to_string(data.scenes.size()) + " scenes (1 to " +
                  std::to_string(kMaxScenes) + " allowed)");
  for (size_t i = 0; i < data.scenes.size(); ++i)
    if (std::string problem = sceneNameProblem(data.scenes[i], i); !problem.empty())
      return refuse(problem);
  if (std::string problem = metadataProblem(data.metadata); !problem.empty())
    return refuse(problem);
  for (size_t i = 0; i < data.samples.size(); ++i)
    if (auto problem = datasetSampleProblem(data.samples[i], data.targetCount, data.scenes.size()))
      return refuse("sample " + std::to_string(i) + ": " + problem->text);
  std::string out;
  out.reserve(64 + data.samples.size() * sampleBytes(data.targetCount));
  out.append(kMagic, sizeof kMagic);
  put<uint32_t>(out, kDatasetVersion);
  put<uint32_t>(out, kDkbFeatureCount);
  put<uint32_t>(out, data.targetCount);
  put<uint32_t>(out, static_cast<uint32_t>(data.scenes.size()));
  for (const std::string& name : data.scenes) {
    put<uint32_t>(out, static_cast<uint32_t>(name.size()));
    out += name;
  }
  put<uint32_t>(out, static_cast<uint32_t>(data.metadata.size()));
  out += data.metadata;
  put<uint64_t>(out, data.samples.size());
  for (const DatasetSample& s : data.samples) {
    put(out, s.scene);
    put(out, s.view);
    put(out, s.budgetStep);
    put(out, s.pixel);
    for (float f : s.features) put(out, f);
    if (data.targetCount == 1)
      put(out, s.target);
    else if (data.targetCount == kDfaoitTargetCount)
      for (float t : s.colour) put(out, t);
    else
      for (uint32_t t = 0; t < data.targetCount; ++t) put(out, s.curve[t]);
  }
  // a temporary file renamed into place: an interrupted write never leaves a truncated dataset
  if (auto written = writeFileAtomically(path, out); !written)
    return makeError("dataset " + written.error().message);
  return {};
}

Result<Dataset> readDataset(const std::string& path) {
  // opened once, every check on the descriptor (a FIFO or device would block or never end)
  auto file = openRegularFile(path, "dataset " + echoPath(path));
  if (!file) return file.error();
  auto read = file->readText();
  if (!read) return read.error();
  const std::string& bytes = *read;
  Reader in(bytes, path);
  std::string magic;
  if (!in.getString(magic, sizeof kMagic) || std::memcmp(magic.data(), kMagic, sizeof kMagic) != 0)
    return makeError("dataset " + echoPath(path) + ": not an mfr dataset (bad magic)");
  uint32_t version = 0, features = 0, targets = 0, sceneCount = 0;
  if (!in.get(version)) return in.error("truncated header");
  if (version != kDatasetVersion)
    return in.error("version " + std::to_string(version) + " is not supported (this build reads " +
                    std::to_string(kDatasetVersion) + ")");
  if (!in.get(features) || !in.get(targets) || !in.get(sceneCount))
    return in.error("truncated header");
  if (features != kDkbFeatureCount)
    return in.error(std::to_string(features) + " features per sample, expected 12");
  if (targets != 1 && targets != kCurveOutputs && targets != kDfaoitTargetCount)
    return in.error(std::to_string(targets) + " targets per sample, expected 1, " +
                    std::to_string(kDfaoitTargetCount) + " or " + std::to_string(kCurveOutputs));
  if (sceneCount == 0 || sceneCount > kMaxScenes) return in.error("bad scene count");
  Dataset data;
  data.fileHash = fnv1a64(bytes);
  data.targetCount = targets;
  const size_t perSample = sampleBytes(targets);
  for (uint32_t i = 0; i < sceneCount; ++i) {
    uint32_t length = 0;
    std::string name;
    if (!in.get(length) || length == 0 || length > kMaxName || !in.getString(name, length))
      return in.error("truncated or bad scene name");
    if (std::string problem = sceneNameProblem(name, i); !problem.empty())
      return makeError("dataset " + echoPath(path) + ": " + problem);
    data.scenes.push_back(std::move(name));
  }
  uint32_t metadataLength = 0;
  if (!in.get(metadataLength) || metadataLength > kMaxMetadata ||
      !in.getString(data.metadata, metadataLength))
    return in.error("truncated or bad metadata");
  if (std::string problem = metadataProblem(data.metadata); !problem.empty())
    return makeError("dataset " + echoPath(path) + ": " + problem);
  uint64_t count = 0;
  if (!in.get(count)) return in.error("truncated sample count");
  if (count > in.remaining() / perSample)
    return in.error("truncated: " + std::to_string(count) + " samples declared, room for " +
                    std::to_string(in.remaining() / perSample));
  if (in.remaining() != count * perSample) return in.error("trailing bytes after the samples");
  data.samples.resize(count);
  for (uint64_t i = 0; i < count; ++i) {
    DatasetSample& s = data.samples[i];
    (void)(in.get(s.scene) && in.get(s.view) && in.get(s.budgetStep) && in.get(s.pixel));
    for (float& f : s.features) (void)in.get(f);
    if (targets == 1)
      (void)in.get(s.target);
    else if (targets == kDfaoitTargetCount)
      for (float& t : s.colour) (void)in.get(t);
    else
      for (uint32_t t = 0; t < targets; ++t) (void)in.get(s.curve[t]);
    if (auto problem = datasetSampleProblem(s, targets, sceneCount))
      return in.error("sample " + std::to_string(i) + ": " + problem->text);
  }
  return data;
}

Result<Compositing> datasetRule(const Dataset& data, const std::string& path) {
  if (std::string problem = metadataProblem(data.metadata); !problem.empty())
    return makeError("dataset " + echoPath(path) + ": " + problem);
  const auto meta = nlohmann::json::parse(data.metadata, nullptr, false);
  if (!meta.is_object() || !meta.contains("composite")) return Compositing::Hybrid;
  const auto& declared = meta["composite"];
  if (declared.is_string()) {
    auto rule = parseCompositing(declared.get<std::string>());
    if (rule && kBufferFamilyRule(rule.value())) return rule.value();
  }
  return makeError("dataset " + echoPath(path) + ": its metadata declares the compositing rule " +
                   jsonExcerpt(declared, 60) + ", expected \"hybrid\" or \"kbuffer\"");
}

Result<void> checkDatasetDefinitions(const Dataset& data, const std::string& path) {
  if (std::string problem = metadataProblem(data.metadata); !problem.empty())
    return makeError("dataset " + echoPath(path) + ": " + problem);
  const auto meta = nlohmann::json::parse(data.metadata, nullptr, false);
  if (!meta.is_object()) return {};
  const bool dfaoit = data.targetCount == kDfaoitTargetCount;
  auto rule = datasetRule(data, path);
  if (!rule) return rule.error();
  const std::pair<const char*, const char*> expected[] = {
      {"features", dfaoit                  ? kDfaoitFeatureSet
                   : data.targetCount == 1 ? kDkbFeatureSet
                                           : dkbCurveFeatureSet(rule.value())},
      {"target", dfaoit                  ? kDfaoitTarget
                 : data.targetCount == 1 ? kDkbTargetScaling
                                         : dkbCurveTarget(rule.value())}};
  for (const auto& [key, value] : expected) {
    const auto it = meta.find(key);
    if (it == meta.end()) continue;
    if (!it->is_string() || it->get<std::string>() != value)
      return makeError("dataset " + echoPath(path) + ": its metadata declares " + key + " " +
                       jsonExcerpt(*it, 120) + ", this build computes \"" + value +
                       "\" (regenerate it with mfr dataset)");
  }
  return {};
}

}  // namespace mfr::learn
