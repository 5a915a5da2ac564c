// What the rendering tests of hand-made glTF quads share: loading a glTF document from text, the
// head-on camera whose view is exactly the quad x, y in [-1, 1], an A-buffer render of a scene and
// the per-pixel comparison of a render with colours computed independently in the test.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>

#include <glm/glm.hpp>

#include "mfr/core/result.hpp"
#include "mfr/cpu/raster_frame.hpp"
#include "mfr/cpu/render.hpp"
#include "mfr/method/method.hpp"
#include "mfr/scene/camera.hpp"
#include "mfr/scene/load.hpp"

namespace mfr::test {

/// Loads glTF `text` through a temporary file named after `tag` and the process (removed again).
inline Result<Scene> loadGltfText(const std::string& text, const std::string& tag) {
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() / (tag + "_" + std::to_string(::getpid()) + ".gltf");
  std::ofstream(path) << text;
  auto scene = loadScene(path.string());
  std::filesystem::remove(path);
  return scene;
}

/// Head-on camera whose view is exactly the quad x, y in [-1, 1], z = 0 (|n.v| within 3e-4 of 1).
inline Camera headOnQuadCamera() {
  Camera camera;
  camera.fovYDegrees = 2.0f;
  const float d = 1.0f / std::tan(glm::radians(1.0f));
  camera.eye = {0.0f, 0.0f, d};
  camera.target = {0.0f, 0.0f, 0.0f};
  camera.zNear = 0.5f * d;
  camera.zFar = 2.0f * d;
  return camera;
}

/// The exact A-buffer's render of `scene` from `camera` at size x size over `background`.
inline RenderOutput renderAbuffer(const Scene& scene, const Camera& camera, int size,
                                  glm::dvec3 background) {
  auto frame = RasterFrame::build(scene, camera, RasterOptions{size, size, 16, 2});
  EXPECT_TRUE(frame.ok()) << frame.error().message;
  RenderOptions options;
  options.background = glm::vec3(background);
  auto out = render(*frame, methodPreset("abuffer").value(), options);
  EXPECT_TRUE(out.ok()) << out.error().message;
  return std::move(*out);
}

/// A rendered pixel against its expectation: within 0.01 in each linear channel (sRGB8 fragment
/// colours, at most half a code: 0.0045 in linear at 1; 8-bit alpha). A miss counts in `wrong`
/// and the first five are reported with the pixel.
inline void expectLinearPixel(glm::vec3 got, glm::dvec3 e, int px, int py, int& wrong) {
  const bool close =
      std::abs(got.r - e.r) < 0.01 && std::abs(got.g - e.g) < 0.01 && std::abs(got.b - e.b) < 0.01;
  if (!close && ++wrong <= 5)
    ADD_FAILURE() << "pixel (" << px << ", " << py << "): got (" << got.r << ", " << got.g << ", "
                  << got.b << "), expected (" << e.r << ", " << e.g << ", " << e.b << ")";
}

}  // namespace mfr::test
