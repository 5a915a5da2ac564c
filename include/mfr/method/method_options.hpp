// Which method options apply to which presets: one table, read by the command line's help texts
// and by its checks, so an option that would change nothing for the chosen method is refused
// instead of silently ignored.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "mfr/core/result.hpp"
#include "mfr/method/method.hpp"

namespace mfr {

enum class MethodOption : uint8_t {
  K,                 // --k: explicit k (fixed, counted; the cap of dynamic k)
  OccupancyD,        // --occupancy-d: bucket words of occupancy culling
  Model,             // --model: the deep k-buffer's network
  ImportanceMap,     // --importance-map: write I(p)
  ImportanceParams,  // vkb's Eq. 3-6 parameters and factor switches, --importance-factors
  Composite,         // --composite kbuffer|hybrid: the k-buffer family and depth peeling (its
                     // tail; not wboit, mboit, mlab)
  MaxPeels,          // --max-peels: the geometry passes of depth peeling (peel, dual-peel)
};

struct MethodOptionRule {
  MethodOption option;
  const char* flags;      // as typed on the command line
  const char* appliesTo;  // in words, for help texts and errors
  bool (*applies)(const MethodDesc&);
};

/// Every rule, one per MethodOption, in enum order.
const std::vector<MethodOptionRule>& methodOptionRules();

const MethodOptionRule& methodOptionRule(MethodOption option);

/// The presets (presetNames(), and their +occupancy forms for OccupancyD) the option applies to,
/// comma-separated.
std::string presetsAccepting(MethodOption option);

/// Ok when the option applies to the method, else a one-line error naming the flag (`typed`, or
/// the rule's flags), the method and the presets it applies to.
Result<void> checkMethodOption(MethodOption option, const MethodDesc& method,
                               const std::string& typed = "");

}  // namespace mfr
