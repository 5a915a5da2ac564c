#include "frame_renderer.hpp"

#include <algorithm>
#include <chrono>
#include <type_traits>

#include "mfr/core/colormap.hpp"
#include "mfr/core/quote.hpp"
#include "mfr/method/make_method.hpp"
#include "mfr/metrics/flip.hpp"
#include "mfr/metrics/image_metrics.hpp"

namespace mfr::view {

struct FrameRenderer::Cached {
  std::string cameraKey;
  std::unique_ptr<PreparedView> view;
  std::optional<RenderOutput> truth;
  std::string truthError;
  std::optional<std::vector<uint32_t>> counts;
  std::string methodKey;
  std::optional<RenderOutput> output;
  std::string error;
  Image8 image, truthImage;
  std::optional<FlipResult> flip;
  std::optional<double> psnr;
};

namespace {

template <class T>
Image8 mapImage(const std::vector<T>& values, int w, int h, const std::string& title) {
  std::vector<float> v(values.begin(), values.end());
  float maxValue = std::is_integral_v<T> ? 1.0f : 0.0f;
  for (float x : v) maxValue = std::max(maxValue, x);
  return colorMapWithLegend(v, w, h, maxValue, title);
}

Image8 blank(int w, int h) {
  Image8 image;
  image.width = w;
  image.height = h;
  image.rgba.assign(static_cast<size_t>(w) * h * 4, 40);
  for (size_t i = 3; i < image.rgba.size(); i += 4) image.rgba[i] = 255;
  return image;
}

}  // namespace

Result<MethodDesc> settingsMethod(const ViewSettings& s) {
  MethodOverrides o;  // the panel keeps its settings across methods: those a method lacks wait
  o.ignoreInapplicable = true;
  if (s.k > 0) o.k = s.k;
  if (!s.composite.empty()) o.composite = s.composite;
  if (s.occupancyD > 0) o.occupancyD = s.occupancyD;
  if (s.maxPeels > 0) o.maxPeels = s.maxPeels;
  if (!s.model.empty()) o.modelPath = s.model;
  o.importance = ImportanceOverrides::all(s.importance);
  o.seed = s.importance.seed;
  return makeMethod(s.method, o);
}

FrameRenderer::FrameRenderer(Engine& engine, const EngineContext& context, GLFWwindow* window,
                             const cli::PreparedScene& scene, const cli::SceneOptions& options)
    : engine_(engine),
      context_(context),
      window_(window),
      windowThread_(std::this_thread::get_id()),
      scene_(scene),
      options_(options),
      cache_(std::make_unique<Cached>()) {}

FrameRenderer::~FrameRenderer() {
  EngineContext::Scope scope(context_, window_);  // the engine's objects die in its context
  cache_.reset();
}

Frame FrameRenderer::update(const ViewSettings& s) {
  const auto start = std::chrono::steady_clock::now();
  Frame f;
  Cached& c = *cache_;
  const int w = options_.width, h = options_.height;
  {
    // a worker leaves the window's context alone: it is current on the window's thread
    EngineContext::Scope scope(context_,
                               std::this_thread::get_id() == windowThread_ ? window_ : nullptr);
    RenderOptions ro;
    ro.background = scene_.scene.background;
    ro.memoryLimitBytes = options_.memoryLimitBytes().value();
    const std::string cameraKey = s.camera.spec();
    if (!c.view || c.cameraKey != cameraKey) {
      c = Cached{};
      auto view = engine_.prepare(cli::sceneView(scene_, options_, s.camera.camera()));
      if (!view) {
        f.error = echoPath(options_.source) + ": " + view.error().message;
        f.display = blank(w, h);
        return f;
      }
      c.view = std::move(view.value());
      c.cameraKey = cameraKey;
    }
    const bool truthView = s.mode == ViewMode::GroundTruth || s.mode == ViewMode::FlipError ||
                           s.mode == ViewMode::Wiper;
    if ((s.compare || truthView) && !c.truth && c.truthError.empty()) {  // ground truth, lazily
      auto truth = engine_.render(*c.view, methodPreset("abuffer").value(), ro);
      if (truth) {
        c.truth = std::move(truth.value());
        c.truthImage = encodeSrgb(c.truth->image);
      } else {
        c.truthError = "A-buffer: " + truth.error().message;
      }
    }
    if (c.methodKey != s.methodKey()) {
      c.methodKey = s.methodKey();
      c.output.reset();
      c.error.clear();
      c.flip.reset();
      c.psnr.reset();
      auto method = settingsMethod(s);
      if (s.budgetBytes > 0) ro.budgetBytes = s.budgetBytes;
      auto out = method ? engine_.render(*c.view, method.value(), ro)
                        : Result<RenderOutput>(method.error());
      if (out) {
        c.output = std::move(out.value());
        c.image = encodeSrgb(c.output->image);
      } else {
        c.error = out.error().message;
      }
    }
    if (c.output && c.truth && !c.flip) {  // the error against the ground truth
      if (auto flip = computeFlip(c.truthImage, c.image)) c.flip = std::move(flip.value());
      if (auto e = compareImages(c.truthImage, c.image)) c.psnr = e->psnrLinear;
    }
    if (s.mode == ViewMode::DepthComplexity && !c.counts) {
      if (c.output && !c.output->depthComplexity.empty())
        c.counts = c.output->depthComplexity;
      else if (c.truth && !c.truth->depthComplexity.empty())
        c.counts = c.truth->depthComplexity;
      else if (auto n = engine_.countFragments(*c.view))
        c.counts = std::move(n.value());
    }
  }
  if (c.output) {
    f.stats = c.output->stats;
    if (c.flip) f.flipMean = c.flip->mean;
    f.psnr = c.psnr;
  }
  f.error = c.error;
  if (c.truth) f.truthBytes = c.truth->stats.bytesUsed;
  const bool needsMethod = s.mode != ViewMode::GroundTruth && s.mode != ViewMode::DepthComplexity;
  const bool needsTruth =
      s.mode == ViewMode::GroundTruth || s.mode == ViewMode::FlipError || s.mode == ViewMode::Wiper;
  if (needsTruth && !c.truth) {
    f.error = c.truthError;
    f.display = blank(w, h);
  } else if (needsMethod && !c.output) {
    f.display = blank(w, h);
  } else {
    switch (s.mode) {
      case ViewMode::Image:
        f.display = c.image;
        break;
      case ViewMode::DepthComplexity:
        if (c.counts)
          f.display = mapImage(*c.counts, w, h, "fragments per pixel");
        else
          f.display = blank(w, h);
        break;
      case ViewMode::KMap:
        f.display = mapImage(c.output->kMap, w, h, "k(p)");
        break;
      case ViewMode::Importance:
        if (c.output->importance.importance.empty()) {
          f.error = "importance: only the importance methods (vkb*, dkb*) have a map";
          f.display = blank(w, h);
        } else {
          f.display = mapImage(c.output->importance.importance, w, h, "importance I(p)");
        }
        break;
      case ViewMode::GroundTruth:
        f.display = c.truthImage;
        break;
      case ViewMode::FlipError:
        f.display = c.flip ? flipErrorImage(*c.flip) : blank(w, h);
        break;
      case ViewMode::Wiper: {
        f.display = c.image;
        const int split = std::clamp(static_cast<int>(s.wiper * w + 0.5f), 0, w);
        for (int y = 0; y < h; ++y)
          for (int x = split; x < w; ++x)
            for (int ch = 0; ch < 4; ++ch) {
              const size_t i = (static_cast<size_t>(y) * w + x) * 4 + ch;
              f.display.rgba[i] = c.truthImage.rgba[i];
            }
        if (split > 0 && split < w)
          for (int y = 0; y < h; ++y)
            for (int ch = 0; ch < 3; ++ch)  // an orange line between the two
              f.display.rgba[(static_cast<size_t>(y) * w + split) * 4 + ch] =
                  static_cast<uint8_t>(ch == 0   ? 255
                                       : ch == 1 ? 140
                                                 : 0);
        break;
      }
    }
  }
  f.renderMs =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return f;
}

}  // namespace mfr::view
