// The GL engine's per-pass times as a GPU user reads them (bench_engines, gpu_check): the GPU time
// of GL_TIME_ELAPSED queries (RenderStats::engineCounters "gpu_ms_PASS") where the driver's timer
// queries are usable, the wall time around each pass (glFinish included; RenderStats::passes)
// otherwise, each labelled as which. A software rasterizer's queries are not usable: Mesa's
// llvmpipe, for one, leaves compute dispatches out (about 0.05 ms for a 100 ms resolve). Passes on
// the host, and a variable-k allocation's passes, have no query: always wall time.
#pragma once

#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>
#include <vector>

#include "mfr/method/render_output.hpp"

namespace mfr::bench {

enum class PassTimer { Gpu, Wall };

inline const char* toString(PassTimer timer) {
  return timer == PassTimer::Gpu ? "gpu" : "wall";
}

/// Gpu unless GL_RENDERER names a software rasterizer (llvmpipe, softpipe, SwiftShader); the
/// environment variable MFR_GL_PASS_TIMER=gpu|wall overrides (e.g. a driver whose queries are off).
inline PassTimer glPassTimer(const std::string& renderer) {
  if (const char* forced = std::getenv("MFR_GL_PASS_TIMER")) {
    if (std::string(forced) == "gpu") return PassTimer::Gpu;
    if (std::string(forced) == "wall") return PassTimer::Wall;
  }
  for (const char* software : {"llvmpipe", "softpipe", "SwiftShader"})
    if (renderer.find(software) != std::string::npos) return PassTimer::Wall;
  return PassTimer::Gpu;
}

/// One pass's time and where it comes from: "gpu" (a timer query) or "wall".
struct TimedPass {
  std::string name;
  double ms = 0.0;
  PassTimer timer = PassTimer::Wall;
};

/// The passes of a GL frame in order, each by `timer` where the pass has a GPU time, else wall.
inline std::vector<TimedPass> glPassTimes(const RenderStats& stats, PassTimer timer) {
  std::vector<TimedPass> out;
  for (const PassTime& p : stats.passes) {
    const auto gpu = stats.engineCounters.find("gpu_ms_" + p.name);
    if (timer == PassTimer::Gpu && gpu != stats.engineCounters.end())
      out.push_back({p.name, gpu->second, PassTimer::Gpu});
    else
      out.push_back({p.name, p.ms, PassTimer::Wall});
  }
  return out;
}

/// "count=1.234;capture=5.678;allocate (host)=0.100[wall]": name=ms per pass, in order; with
/// `markWall` a pass timed by the wall clock carries "[wall]" (among GPU times).
inline std::string passList(const std::vector<TimedPass>& passes, bool markWall) {
  std::string out;
  for (const TimedPass& p : passes) {
    char ms[48];
    std::snprintf(ms, sizeof ms, "%.3f", p.ms);
    if (!out.empty()) out += ';';
    out += p.name + "=" + ms;
    if (markWall && p.timer == PassTimer::Wall) out += "[wall]";
  }
  return out;
}

}  // namespace mfr::bench
