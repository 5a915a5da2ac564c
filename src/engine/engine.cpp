// makeEngine and the Engine helpers (mfr/engine/engine.hpp).
#include "mfr/engine/engine.hpp"

#include "mfr/core/quote.hpp"
#include "mfr/cpu/cpu_engine.hpp"

namespace mfr {

Result<RenderOutput> Engine::render(const View& view, const MethodDesc& method,
                                    const RenderOptions& options) {
  auto prepared = prepare(view);
  if (!prepared) return prepared.error();
  return render(**prepared, method, options);
}

std::vector<std::string> engineNames() {
  return {"cpu"};
}

Result<std::unique_ptr<Engine>> makeEngine(std::string_view name, const EngineOptions& options) {
  if (name == "cpu") return std::unique_ptr<Engine>(std::make_unique<CpuEngine>(options));
  std::string known;
  for (const std::string& n : engineNames()) known += (known.empty() ? "" : ", ") + n;
  return makeError("--engine " + quoteInput(name) + ": unknown engine (known: " + known + ")");
}

}  // namespace mfr
