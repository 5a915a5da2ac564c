#include "script.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include "mfr/core/image.hpp"
#include "mfr/core/json_limits.hpp"
#include "mfr/core/quote.hpp"
#include "mfr/core/units.hpp"
#include "mfr/method/method.hpp"

namespace mfr::view {

namespace {

// `const auto var = expr.value()`, or return expr's error
#define MFR_VIEW_GET(var, expr)                   \
  auto var##_result = (expr);                     \
  if (!var##_result) return var##_result.error(); \
  const auto var = var##_result.value()

Result<double> number(const nlohmann::json& v, const std::string& key) {
  if (!v.is_number() || !std::isfinite(v.get<double>()))
    return makeError("\"" + key + "\": expected a number");
  return v.get<double>();
}

Result<std::string> text(const nlohmann::json& v, const std::string& key) {
  if (!v.is_string()) return makeError("\"" + key + "\": expected a string");
  return v.get<std::string>();
}

}  // namespace

Result<void> applyStep(const nlohmann::json& step, ViewSettings& s, FrameActions& actions) {
  if (!step.is_object()) return makeError("expected an object of actions");
  for (const auto& [key, value] : step.items()) {
    if (key == "method") {
      MFR_VIEW_GET(name, text(value, key));
      if (auto preset = methodPreset(name); !preset) return preset.error();
      s.method = name;
    } else if (key == "composite") {
      MFR_VIEW_GET(rule, text(value, key));
      if (!rule.empty())
        if (auto parsed = parseCompositing(rule); !parsed)
          return makeError("\"composite\": " + parsed.error().message);
      s.composite = rule;
    } else if (key == "budget_mb") {
      MFR_VIEW_GET(mb, number(value, key));
      if (!(mb >= 0.0 && mb <= 1024.0 * 1024.0)) return makeError("\"budget_mb\": out of range");
      s.budgetBytes = static_cast<uint64_t>(std::llround(mb * 1048576.0));
    } else if (key == "budget") {
      MFR_VIEW_GET(size, text(value, key));
      auto bytes = parseByteSize(size);
      if (!bytes) return makeError("\"budget\": " + bytes.error().message);
      s.budgetBytes = bytes.value();
    } else if (key == "k") {
      MFR_VIEW_GET(k, number(value, key));
      if (!(k >= 0.0 && k <= 1048576.0)) return makeError("\"k\": must be in [0, 1048576]");
      s.k = static_cast<uint32_t>(k);
    } else if (key == "mode") {
      MFR_VIEW_GET(name, text(value, key));
      auto mode = parseViewMode(name);
      if (!mode)
        return makeError("\"mode\": " + quoteInput(name) +
                         ": expected image, depth, kmap, importance, truth, flip or wiper");
      s.mode = *mode;
    } else if (key == "wiper") {
      MFR_VIEW_GET(x, number(value, key));
      s.wiper = static_cast<float>(std::clamp(x, 0.0, 1.0));
    } else if (key == "orbit") {
      MFR_VIEW_GET(a, number(value, key));
      s.camera.orbit(static_cast<float>(a), 0.0f);
    } else if (key == "pitch") {
      MFR_VIEW_GET(a, number(value, key));
      s.camera.orbit(0.0f, static_cast<float>(a));
    } else if (key == "zoom") {
      MFR_VIEW_GET(z, number(value, key));
      if (!(z > 0.0)) return makeError("\"zoom\": must be > 0");
      s.camera.zoom(static_cast<float>(z));
    } else if (key == "fov") {
      MFR_VIEW_GET(fov, number(value, key));
      s.camera.setFov(static_cast<float>(fov));
    } else if (key == "pan") {
      if (!value.is_array() || value.size() != 2 || !value[0].is_number() || !value[1].is_number())
        return makeError("\"pan\": expected [dx, dy]");
      s.camera.pan(value[0].get<float>(), value[1].get<float>());
    } else if (key == "fly") {
      if (!value.is_array() || value.size() != 3 || !value[0].is_number() ||
          !value[1].is_number() || !value[2].is_number())
        return makeError("\"fly\": expected [right, up, forward]");
      s.camera.fly(value[0].get<float>(), value[1].get<float>(), value[2].get<float>());
    } else if (key == "file_camera") {
      MFR_VIEW_GET(n, number(value, key));
      if (!(n >= 0.0 && n < 1e6)) return makeError("\"file_camera\": expected a camera index");
      actions.fileCamera = static_cast<int>(n);
    } else if (key == "next_camera") {
      MFR_VIEW_GET(n, number(value, key));
      if (n != 1.0 && n != -1.0) return makeError("\"next_camera\": expected 1 or -1");
      actions.nextCamera = static_cast<int>(n);
    } else if (key == "open") {
      MFR_VIEW_GET(path, text(value, key));
      actions.open = path;
    } else if (key == "occupancy_d") {
      MFR_VIEW_GET(d, number(value, key));
      if (!(d >= 0.0 && d <= 64.0)) return makeError("\"occupancy_d\": must be in [0, 64]");
      s.occupancyD = static_cast<int>(d);
    } else if (key == "model") {
      MFR_VIEW_GET(path, text(value, key));
      s.model = path;
    } else if (key == "importance") {
      if (!value.is_object()) return makeError("\"importance\": expected an object");
      for (const auto& [name, v] : value.items()) {
        float* param = name == "alpha"         ? &s.importance.alpha
                       : name == "n_limit"     ? &s.importance.nLimit
                       : name == "periphery_d" ? &s.importance.peripheryExponent
                       : name == "noise"       ? &s.importance.noise
                                               : nullptr;
        bool* flag = name == "depth"        ? &s.importance.useDepth
                     : name == "periphery"  ? &s.importance.usePeriphery
                     : name == "fresnel"    ? &s.importance.useFresnel
                     : name == "noise_term" ? &s.importance.useNoise
                                            : nullptr;
        if (name == "fovea") {  // [x, y] in pixels, or null for the image centre
          if (v.is_null()) {
            s.importance.fovea.reset();
            continue;
          }
          if (!v.is_array() || v.size() != 2 || !v[0].is_number() || !v[1].is_number() ||
              !std::isfinite(v[0].get<double>()) || !std::isfinite(v[1].get<double>()))
            return makeError("\"importance.fovea\": expected [x, y] in pixels or null");
          s.importance.fovea = glm::vec2(v[0].get<float>(), v[1].get<float>());
        } else if (param) {
          MFR_VIEW_GET(x, number(v, "importance." + name));
          *param = static_cast<float>(x);
        } else if (flag) {
          if (!v.is_boolean()) return makeError("\"importance." + name + "\": expected a boolean");
          *flag = v.get<bool>();
        } else {
          return makeError("\"importance\": unknown parameter \"" + name + "\"");
        }
      }
    } else if (key == "budget_share") {
      MFR_VIEW_GET(share, number(value, key));
      if (!(share >= 0.0 && share <= 1000.0)) return makeError("\"budget_share\": out of range");
      actions.budgetShare = share;
    } else if (key == "reset") {
      s.camera.reset();
    } else if (key == "compare") {
      if (!value.is_boolean()) return makeError("\"compare\": expected true or false");
      s.compare = value.get<bool>();
    } else if (key == "screenshot") {
      MFR_VIEW_GET(path, text(value, key));
      MFR_TRY(imageOutputFormat("\"screenshot\"", path, {OutputImageFormat::Png}));
      actions.screenshots.push_back(path);
    } else if (key == "screenshot_maps") {
      MFR_VIEW_GET(prefix, text(value, key));
      actions.screenshotMaps.push_back(prefix);
    } else if (key == "screenshot_ui") {
      MFR_VIEW_GET(path, text(value, key));
      MFR_TRY(imageOutputFormat("\"screenshot_ui\"", path, {OutputImageFormat::Png}));
      actions.screenshotsUi.push_back(path);
    } else if (key == "copy_command") {
      actions.copyCommand = true;
    } else {
      return makeError("unknown action \"" + key + "\"");
    }
  }
  return {};
}

Result<std::vector<nlohmann::json>> loadScript(const std::string& path) {
  std::ifstream in(path);
  if (!in) return makeError("--script " + echoPath(path) + ": cannot read the file");
  std::stringstream buffer;
  buffer << in.rdbuf();
  const std::string text = buffer.str();
  // before the steps are copied (a copy recurses once per level of nesting)
  if (const std::string deep = jsonDepthProblem(text); !deep.empty())
    return makeError("--script " + echoPath(path) + ": " + deep);
  nlohmann::json doc = nlohmann::json::parse(text, nullptr, false);
  if (doc.is_discarded() || !doc.is_array())
    return makeError("--script " + echoPath(path) + ": expected a JSON array of action objects");
  std::vector<nlohmann::json> steps(doc.begin(), doc.end());
  // check every step on a scratch copy, so a typo fails before the window opens
  ViewSettings scratch{Camera{}};
  for (size_t i = 0; i < steps.size(); ++i) {
    FrameActions ignored;
    if (auto ok = applyStep(steps[i], scratch, ignored); !ok)
      return makeError("--script " + echoPath(path) + ": step " + std::to_string(i) + ": " +
                       ok.error().message);
  }
  return steps;
}

}  // namespace mfr::view
