// Built-in procedural scenes, deterministic from a seed, mimicking the papers' test cases.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "mfr/core/result.hpp"
#include "mfr/scene/scene.hpp"

namespace mfr {

using ProceduralParams = std::map<std::string, std::string>;

/// Names of the built-in scenes: layers, hairball, smoke, bottles, spheres.
std::vector<std::string> proceduralSceneNames();

/// Builds "NAME[?key=value&...]" (the part after "procedural:"). Unknown names or parameters, and
/// values that do not parse or are out of range, are errors naming them.
Result<Scene> makeProceduralScene(const std::string& spec, uint64_t seed);

}  // namespace mfr
