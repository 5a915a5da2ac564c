// The --camera string "EX,EY,EZ,TX,TY,TZ[,UX,UY,UZ[,FOV]]" (parseCameraSpec), then what the
// camera does to the rasterizer: clip planes fitted to a small scene, set-up and clipping, and a
// render, for any accepted camera (far away, inside the scene, extreme fields of view).
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fuzz_util.hpp"
#include "mfr/scene/camera_spec.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  auto camera = mfr::parseCameraSpec(text, "--camera");
  if (!camera) {
    mfr::fuzz::checkError(camera.error(), "--camera");
    return 0;
  }
  static const mfr::MethodDesc abuffer = mfr::methodPreset("abuffer").value();
  static const mfr::MethodDesc kplus = [] {
    mfr::MethodDesc m = mfr::methodPreset("kplus-heap+occupancy").value();
    m.k = 2;
    m.compositing = mfr::Compositing::Hybrid;
    return m;
  }();
  mfr::fuzz::renderChecked(mfr::fuzz::smallScene(), camera.value(), 10, abuffer);
  mfr::fuzz::renderChecked(mfr::fuzz::smallScene(), camera.value(), 10, kplus);
  return 0;
}
