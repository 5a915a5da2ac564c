// Stanford PLY, ASCII and binary (both byte orders): mfr's structure check (PlyChecker) and, for
// files it accepts, assimp's PLY importer; then the loaded scene is rendered.
#include <cstddef>
#include <cstdint>

#include "fuzz_util.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  mfr::fuzz::loadAndExercise(mfr::fuzz::workDir().write("scene.ply", data, size));
  return 0;
}
