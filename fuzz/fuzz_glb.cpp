// Binary glTF (.glb): the 12-byte header, the JSON and BIN chunks, images in buffer views, then
// everything fuzz_gltf.cpp checks. Helper files as in fuzz_gltf.cpp.
#include <cstddef>
#include <cstdint>

#include "fuzz_util.hpp"
#include "gltf_helpers.hpp"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  mfr::fuzz::writeGltfHelpers(mfr::fuzz::workDir());
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto& dir = mfr::fuzz::workDir();
  mfr::fuzz::loadAndExercise(dir.write("scene.glb", data, size));
  return 0;
}
