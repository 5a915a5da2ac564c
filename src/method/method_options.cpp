// The table of method options and the presets they apply to (method_options.hpp).
#include "mfr/method/method_options.hpp"

#include "mfr/method/peel.hpp"

namespace mfr {
namespace {

bool takesK(const MethodDesc& m) {
  switch (m.allocation) {
    case AllocationPolicy::FixedK:
    case AllocationPolicy::CountedK:
    case AllocationPolicy::DynamicK:
      return true;
    case AllocationPolicy::Unbounded:
    case AllocationPolicy::Importance:
    case AllocationPolicy::Optimal:
    case AllocationPolicy::NoNodes:
    case AllocationPolicy::Pool:
      return false;
  }
  return false;
}

bool importanceMethod(const MethodDesc& m) {
  return m.allocation == AllocationPolicy::Importance;
}

bool heuristicImportance(const MethodDesc& m) {
  return m.allocation == AllocationPolicy::Importance &&
         m.importanceSource == ImportanceSource::Heuristic;
}

bool networkImportance(const MethodDesc& m) {
  return (m.allocation == AllocationPolicy::Importance &&
          m.importanceSource == ImportanceSource::Network) ||
         m.predictedCurves;
}

bool occupancy(const MethodDesc& m) {
  return m.occupancyWords > 0;
}

bool kBufferFamily(const MethodDesc& m) {
  return kBufferFamilyRule(m.compositing) || peelingRule(m.compositing);
}

bool peeling(const MethodDesc& m) {
  return peelingRule(m.compositing);
}

}  // namespace

const std::vector<MethodOptionRule>& methodOptionRules() {
  static const std::vector<MethodOptionRule> rules = {
      {MethodOption::K, "--k", "fixed, counted and dynamic k (the dynamic k's upper bound)",
       takesK},
      {MethodOption::OccupancyD, "--occupancy-d", "methods with +occupancy", occupancy},
      {MethodOption::Model, "--model", "the deep k-buffer (dkb, dkb-fill, dkb-curve)",
       networkImportance},
      {MethodOption::ImportanceMap, "--importance-map", "importance allocation (vkb, dkb)",
       importanceMethod},
      {MethodOption::ImportanceParams,
       "--importance-alpha/--n-limit/--periphery-d/--fovea/--noise/--no-*-term/"
       "--importance-factors",
       "the variable k-buffer's heuristic importance", heuristicImportance},
      {MethodOption::Composite, "--composite",
       "the k-buffer family (kbuffer / hybrid rules) and depth peeling (hybrid: a tail after "
       "--max-peels)",
       kBufferFamily},
      {MethodOption::MaxPeels, "--max-peels", "depth peeling", peeling},
  };
  return rules;
}

const MethodOptionRule& methodOptionRule(MethodOption option) {
  return methodOptionRules()[static_cast<size_t>(option)];
}

std::string presetsAccepting(MethodOption option) {
  const MethodOptionRule& rule = methodOptionRule(option);
  std::string list;
  for (const std::string& name : presetNames()) {
    const std::string full = option == MethodOption::OccupancyD ? name + "+occupancy" : name;
    auto preset = methodPreset(full);
    if (!preset || !rule.applies(preset.value())) continue;
    if (!list.empty()) list += ", ";
    list += full;
  }
  return list;
}

Result<void> checkMethodOption(MethodOption option, const MethodDesc& method,
                               const std::string& typed) {
  const MethodOptionRule& rule = methodOptionRule(option);
  if (rule.applies(method)) return {};
  return makeError((typed.empty() ? std::string(rule.flags) : typed) + ": does not apply to " +
                   method.name + " (only to " + rule.appliesTo + ": " + presetsAccepting(option) +
                   ")");
}

}  // namespace mfr
