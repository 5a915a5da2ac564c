// Wavefront OBJ + MTL. The input is the OBJ text, optionally followed by a line "#--mtl--" and the
// text of scene.mtl (written next to scene.obj, which may name it with `mtllib scene.mtl`);
// texture.png (2 x 2) is there for map_Kd. Then the loaded scene is rendered.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fuzz_util.hpp"
#include "gltf_helpers.hpp"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  mfr::fuzz::writeGltfHelpers(mfr::fuzz::workDir());
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto& dir = mfr::fuzz::workDir();
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  constexpr std::string_view kSeparator = "#--mtl--\n";
  const size_t split = input.find(kSeparator);
  if (split == std::string_view::npos) {
    dir.remove("scene.mtl");
    mfr::fuzz::loadAndExercise(dir.write("scene.obj", input));
  } else {
    dir.write("scene.mtl", input.substr(split + kSeparator.size()));
    mfr::fuzz::loadAndExercise(dir.write("scene.obj", input.substr(0, split)));
  }
  return 0;
}
