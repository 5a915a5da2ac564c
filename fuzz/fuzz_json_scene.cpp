// JSON scene files: keys, types and ranges of mesh / cameras / background / alpha /
// transmission_alpha_floor, the mesh reference (mesh.obj next to it, or a procedural spec, capped
// at kMaxFuzzTriangles), and the file's cameras in the render that follows.
#include <cstddef>
#include <cstdint>

#include "fuzz_util.hpp"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  mfr::fuzz::workDir().write("mesh.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 -1\nf 1 2 3\nf 2 4 3\n");
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  mfr::fuzz::loadAndExercise(mfr::fuzz::workDir().write("scene.json", data, size));
  return 0;
}
