// Machine-readable statistics of a run. Stable top-level keys scripts rely on: method,
// budget_bytes, bytes_used, fragments_generated, fragments_captured, fragments_lost, k_min, k_max,
// time_ms (pass name -> milliseconds); more keys may be added.
#pragma once

#include <nlohmann/json.hpp>

#include "mfr/method/render_output.hpp"

namespace mfr {

nlohmann::json statsToJson(const RenderStats& stats);

}  // namespace mfr
