// makeEngine and the Engine helpers (mfr/engine/engine.hpp).
#include "mfr/engine/engine.hpp"

#include "mfr/core/quote.hpp"
#include "mfr/core/suggest.hpp"
#include "mfr/cpu/cpu_engine.hpp"

namespace mfr {

Result<void> Engine::preflight(int, int, const MethodDesc&, const RenderOptions&) const {
  return {};
}

MemoryModel Engine::memoryModel(const MethodDesc& method, const RenderOptions& options) const {
  return MemoryModel::of(method, options.capture == CaptureMode::FragmentParallel);
}

Result<std::vector<uint32_t>> Engine::storageFragmentCounts(const PreparedView& view,
                                                            SampleStorage storage) {
  if (view.samples() == 1) return countFragments(view);
  return makeError("engine " + std::string(name()) + ": no per-" + toString(storage) +
                   " fragment counts at " + std::to_string(view.samples()) + " samples");
}

Result<RenderOutput> Engine::render(const View& view, const MethodDesc& method,
                                    const RenderOptions& options) {
  MFR_TRY(preflight(view.width, view.height, method, options));
  auto prepared = prepare(view);
  if (!prepared) return prepared.error();
  return render(**prepared, method, options);
}

namespace {

Result<std::unique_ptr<Engine>> makeCpuEngine(const EngineOptions& options) {
  return std::unique_ptr<Engine>(std::make_unique<CpuEngine>(options));
}

std::vector<std::pair<std::string, EngineFactory>>& registry() {
  static std::vector<std::pair<std::string, EngineFactory>> engines = {{"cpu", makeCpuEngine}};
  return engines;
}

}  // namespace

void registerEngine(const std::string& name, EngineFactory factory) {
  for (const auto& [known, f] : registry())
    if (known == name) return;
  registry().emplace_back(name, factory);
}

std::vector<std::string> engineNames() {
  std::vector<std::string> names;
  for (const auto& [name, factory] : registry()) names.push_back(name);
  return names;
}

Result<std::unique_ptr<Engine>> makeEngine(std::string_view name, const EngineOptions& options) {
  for (const auto& [known, factory] : registry())
    if (known == name) return factory(options);
  std::string known;
  for (const std::string& n : engineNames()) known += (known.empty() ? "" : ", ") + n;
  const std::string suggestion = didYouMean(name, engineNames());
  return makeError("--engine " + quoteInput(name) + ": unknown engine" +
                   (suggestion.empty() ? "" : "; " + suggestion) + " (known: " + known + ")");
}

}  // namespace mfr
