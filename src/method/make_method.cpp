// makeMethod: a preset plus the user's overrides, checked once for every front end
// (make_method.hpp).
#include "mfr/method/make_method.hpp"

#include <cmath>

#include "mfr/core/quote.hpp"
#include "mfr/core/units.hpp"
#include "mfr/learn/model_file.hpp"
#include "mfr/method/dkb_model.hpp"
#include "mfr/method/method_options.hpp"
#include "mfr/method/peel.hpp"

namespace mfr {
namespace {

/// Python takes the importance parameters as one dict: its keys name them there.
std::string importanceName(Spelling spelling, const char* flag, const char* key) {
  return spelling == Spelling::Cli ? std::string(flag) : "importance['" + std::string(key) + "']";
}

/// A number given for an option must lie in [lo, hi] (or (lo, hi] when `openLow`) as the float
/// the method keeps.
Result<float> inRange(double given, double lo, double hi, bool openLow, const std::string& name,
                      const char* range) {
  const float value = static_cast<float>(given);
  if (!(openLow ? value > lo : value >= lo) || !(value <= hi))
    return makeError(name + ": must be in " + range);
  return value;
}

Result<ImportanceParams> importanceParams(const ImportanceOverrides& o, uint64_t seed,
                                          Spelling spelling) {
  ImportanceParams ip;
  const auto name = [&](const char* flag, const char* key) {
    return importanceName(spelling, flag, key);
  };
  if (o.alpha) {
    auto v = inRange(*o.alpha, 0, 1, false, name("--importance-alpha", "alpha"), "[0, 1]");
    if (!v) return v.error();
    ip.alpha = *v;
  }
  if (o.nLimit) {
    auto v = inRange(*o.nLimit, 1, 1e6, false, name("--n-limit", "n_limit"), "[1, 1e6]");
    if (!v) return v.error();
    ip.nLimit = *v;
  }
  if (o.peripheryD) {
    auto v = inRange(*o.peripheryD, 0, 100, true, name("--periphery-d", "periphery_d"), "(0, 100]");
    if (!v) return v.error();
    ip.peripheryExponent = *v;
  }
  if (o.noise) {
    auto v = inRange(*o.noise, 0, 1, false, name("--noise", "noise"), "[0, 1]");
    if (!v) return v.error();
    ip.noise = *v;
  }
  if (o.fovea) {
    const std::vector<double>& f = *o.fovea;
    if (f.size() != 2 || !std::isfinite(f[0]) || !std::isfinite(f[1]))
      return makeError(name("--fovea", "fovea") + ": expected two finite pixel coordinates X,Y");
    ip.fovea = glm::vec2(f[0], f[1]);
  }
  ip.useDepth = o.depthTerm.value_or(true);
  ip.usePeriphery = o.peripheryTerm.value_or(true);
  ip.useFresnel = o.fresnelTerm.value_or(true);
  ip.useNoise = o.noiseTerm.value_or(true);
  ip.seed = seed;
  return ip;
}

/// Ok when `option` applies to `m`; with ignoreInapplicable, false (the caller skips the option).
Result<bool> takes(MethodOption option, const MethodDesc& m, const MethodOverrides& o,
                   const std::string& typed) {
  if (auto ok = checkMethodOption(option, m, typed); !ok) {
    if (o.ignoreInapplicable) return false;
    return ok.error();
  }
  return true;
}

}  // namespace

std::string ImportanceOverrides::firstGiven() const {
  if (alpha) return "--importance-alpha";
  if (nLimit) return "--n-limit";
  if (peripheryD) return "--periphery-d";
  if (noise) return "--noise";
  if (fovea) return "--fovea";
  if (depthTerm) return "--no-depth-term";
  if (peripheryTerm) return "--no-periphery-term";
  if (fresnelTerm) return "--no-fresnel-term";
  if (noiseTerm) return "--no-noise";
  return "";
}

ImportanceOverrides ImportanceOverrides::all(const ImportanceParams& p) {
  ImportanceOverrides o;
  o.alpha = p.alpha;
  o.nLimit = p.nLimit;
  o.peripheryD = p.peripheryExponent;
  o.noise = p.noise;
  if (p.fovea) o.fovea = std::vector<double>{p.fovea->x, p.fovea->y};
  o.depthTerm = p.useDepth;
  o.peripheryTerm = p.usePeriphery;
  o.fresnelTerm = p.useFresnel;
  o.noiseTerm = p.useNoise;
  return o;
}

Result<MethodDesc> makeMethod(const std::string& name, const MethodOverrides& o,
                              Spelling spelling) {
  auto preset = methodPreset(name);
  if (!preset) return preset.error();
  MethodDesc m = std::move(preset.value());
  const auto flag = [&](const char* cli) { return spell(spelling, cli); };

  if (o.k) {
    auto applies = takes(MethodOption::K, m, o, flag("--k"));
    if (!applies) return applies.error();
    if (*applies) {
      if (*o.k < 1 || *o.k > (1 << 20)) return makeError(flag("--k") + ": must be in [1, 1048576]");
      const bool zbuffer = m.name.rfind("zbuffer", 0) == 0;
      if (zbuffer && *o.k != 1 && !o.ignoreInapplicable)
        return makeError(flag("--k") + ": zbuffer has k = 1");
      if (!zbuffer) m.k = static_cast<uint32_t>(*o.k);
    }
  }
  if (!o.composite.empty()) {  // otherwise the preset's own rule
    auto applies = takes(MethodOption::Composite, m, o, flag("--composite"));
    if (!applies) return applies.error();
    if (*applies) {
      auto rule = parseCompositing(o.composite);
      if (!rule) return makeError(flag("--composite") + ": " + rule.error().message);
      if (peelingRule(m.compositing))  // depth peeling keeps its rule: hybrid adds the tail
        m.peelTail = rule.value() == Compositing::Hybrid;
      else
        m.compositing = rule.value();
    }
  }
  if (o.occupancyD) {
    auto applies = takes(MethodOption::OccupancyD, m, o, flag("--occupancy-d"));
    if (!applies) return applies.error();
    if (*applies) {
      if (*o.occupancyD < 1 || *o.occupancyD > 64)
        return makeError(flag("--occupancy-d") + ": must be in [1, 64]");
      m.occupancyWords = static_cast<int>(*o.occupancyD);
    }
  }
  if (o.maxPeels) {
    auto applies = takes(MethodOption::MaxPeels, m, o, flag("--max-peels"));
    if (!applies) return applies.error();
    if (*applies) {
      if (*o.maxPeels < 1 || *o.maxPeels > kMaxPeels)
        return makeError(flag("--max-peels") + ": must be in [1, " + std::to_string(kMaxPeels) +
                         "]");
      m.maxPeels = static_cast<uint32_t>(*o.maxPeels);
    }
  }
  if (const std::string given = o.importance.firstGiven(); !given.empty() || o.importance.asGroup) {
    const std::string typed = spelling == Spelling::Cli ? given : std::string("importance");
    auto applies = takes(MethodOption::ImportanceParams, m, o, typed);
    if (!applies) return applies.error();
  }
  if (m.allocation == AllocationPolicy::Importance) {
    auto params = importanceParams(o.importance, o.seed, spelling);
    if (!params) return params.error();
    m.importance = params.value();
  }
  if (!o.modelPath.empty() || o.model) {
    auto applies = takes(MethodOption::Model, m, o, flag("--model"));
    if (!applies) return applies.error();
    if (*applies) {
      std::string modelName = o.modelName;
      if (!o.modelPath.empty()) {
        auto model = loadMethodModel(o.modelPath);
        if (!model) return model.error();
        m.model = model.value();
        modelName = o.modelPath;
      } else {
        m.model = o.model;
      }
      if (auto fits = checkModelForMethod(*m.model, modelName, m); !fits)
        return makeError(flag("--model") + ": " + fits.error().message);
    }
  }
  return m;
}

Result<CaptureMode> parseCaptureOption(const std::string& text, Spelling spelling) {
  if (text == "tile") return CaptureMode::TileOwned;
  if (text == "parallel") return CaptureMode::FragmentParallel;
  return makeError(spell(spelling, "--capture") + " " + quoteInput(text) +
                   ": expected tile or parallel");
}

Result<uint64_t> parseMemoryLimitOption(const std::string& text, Spelling spelling) {
  auto bytes = parseByteSize(text);
  if (!bytes)
    return makeError(spell(spelling, "--memory-limit") + " " + quoteInput(text) +
                     ": expected a size such as 8GB, 512MB or 1048576 (at most 1 TiB)");
  return bytes.value();
}

Result<std::shared_ptr<const learn::Model>> loadMethodModel(const std::string& path) {
  auto model = learn::readModel(path);
  if (!model) return model.error();
  // an importance model (dkb, dkb-fill) or a curve model (dkb-curve): which one a method needs
  // is checkModelForMethod's question
  if (auto fits = checkDkbModel(model.value(), path); !fits)
    if (!checkDkbCurveModel(model.value(), path)) return fits.error();
  return std::make_shared<const learn::Model>(std::move(model.value()));
}

Result<void> checkModelUsed(const std::vector<std::string>& methods, Spelling spelling) {
  for (const std::string& name : methods) {
    auto preset = methodPreset(name);
    if (preset && checkMethodOption(MethodOption::Model, preset.value())) return {};
  }
  return makeError(spell(spelling, "--model") + ": none of the methods uses it (only " +
                   methodOptionRule(MethodOption::Model).appliesTo + ": " +
                   presetsAccepting(MethodOption::Model) + ")");
}

Result<void> checkComparisonModel(const learn::Model& model, const std::string& name,
                                  const std::vector<std::string>& methods,
                                  std::optional<Compositing> compositing, Spelling spelling) {
  MFR_TRY(checkModelUsed(methods, spelling));
  for (const std::string& method : methods) {
    auto preset = methodPreset(method);
    if (!preset) return preset.error();
    MethodDesc m = std::move(preset.value());
    if (!checkMethodOption(MethodOption::Model, m)) continue;
    if (compositing) m.compositing = *compositing;
    if (auto ok = checkModelForMethod(model, name, m); !ok)
      return makeError(spell(spelling, "--model") + ": " + ok.error().message);
  }
  return {};
}

}  // namespace mfr
