// Built-in procedural scenes, deterministic from a seed, mimicking the papers' test cases.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "mfr/core/result.hpp"
#include "mfr/scene/scene.hpp"

namespace mfr {

using ProceduralParams = std::map<std::string, std::string>;

/// Names of the built-in scenes: layers, hairball, smoke, bottles, spheres.
std::vector<std::string> proceduralSceneNames();

/// No parameter combination may produce more triangles than this by default (about 2.4 GB of mesh
/// data).
inline constexpr double kMaxProceduralTriangles = 50'000'000.0;

/// Builds "NAME[?key=value&...]" (the part after "procedural:"). Unknown names or parameters, and
/// values that do not parse or are out of range, are errors naming them, as are parameters that
/// would produce more than `maxTriangles` triangles or a scene whose sceneMemoryBytes exceed
/// `memoryLimitBytes` (none: defaultMemoryLimit()), both checked before anything is built.
Result<Scene> makeProceduralScene(const std::string& spec, uint64_t seed,
                                  double maxTriangles = kMaxProceduralTriangles,
                                  std::optional<uint64_t> memoryLimitBytes = std::nullopt);

}  // namespace mfr
