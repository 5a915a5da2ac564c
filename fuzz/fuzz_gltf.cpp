// glTF 2.0 text files (.gltf): tinygltf's parser and mfr's checks on top of it (accessors, sparse
// accessors, node transforms, materials, transmission, texture decoding, cameras), then a render of
// the loaded scene. Buffers and images may be data URIs or buffer.bin / texture.png in the same
// folder (gltf_helpers.hpp).
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
  mfr::fuzz::loadAndExercise(dir.write("scene.gltf", data, size));
  return 0;
}
