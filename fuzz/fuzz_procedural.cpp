// The procedural: query string "NAME[?key=value&...]": names, keys, duplicate keys, integer and
// real values and their ranges, seeds, the triangle cap (lowered to kMaxFuzzTriangles so every
// input stays fast), and a render of the scene built.
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_util.hpp"
#include "mfr/scene/procedural.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string spec(reinterpret_cast<const char*>(data), size);
  auto scene = mfr::makeProceduralScene(spec, 1, mfr::fuzz::kMaxFuzzTriangles);
  if (!scene) {
    mfr::fuzz::checkError(scene.error(), "procedural");
    return 0;
  }
  mfr::fuzz::exerciseScene(scene.value());
  // Through loadScene as the command line calls it: same scene, vertex normals recomputed.
  mfr::LoadOptions options;
  options.maxProceduralTriangles = mfr::fuzz::kMaxFuzzTriangles;
  auto loaded = mfr::loadScene("procedural:" + spec, options);
  FUZZ_CHECK(loaded.ok(), loaded.ok() ? "" : loaded.error().message);
  FUZZ_CHECK(loaded->indices == scene->indices && loaded->positions == scene->positions,
             "loadScene and makeProceduralScene disagree");
  return 0;
}
