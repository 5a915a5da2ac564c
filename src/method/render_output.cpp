// RenderStats helpers (mfr/method/render_output.hpp).
#include "mfr/method/render_output.hpp"

namespace mfr {

double RenderStats::totalMs() const {
  double total = 0.0;
  for (const PassTime& p : passes) total += p.ms;
  return total;
}

}  // namespace mfr
