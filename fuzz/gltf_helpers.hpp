// Files the glTF seeds refer to by relative URI, written next to the fuzzed input once per process:
// buffer.bin (a triangle: 3 float3 positions at 0, 3 float2 uvs at 36, uint16 indices 0 1 2 at
// 60; 68 bytes) and texture.png (2 x 2 RGBA). Mutated inputs can point any buffer or image at them.
#pragma once

#include <cstdint>
#include <cstring>
#include <vector>

#include "fuzz_util.hpp"
#include "mfr/core/image.hpp"

namespace mfr::fuzz {

inline void writeGltfHelpers(const WorkDir& dir) {
  const float positions[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  const float uvs[6] = {0, 0, 1, 0, 0, 1};
  const uint16_t indices[4] = {0, 1, 2, 0};
  std::vector<uint8_t> bytes(68);
  std::memcpy(bytes.data(), positions, sizeof positions);
  std::memcpy(bytes.data() + 36, uvs, sizeof uvs);
  std::memcpy(bytes.data() + 60, indices, sizeof indices);
  dir.write("buffer.bin", bytes.data(), bytes.size());
  Image8 texture;
  texture.width = texture.height = 2;
  texture.rgba = {255, 0, 0, 128, 0, 255, 0, 255, 0, 0, 255, 64, 255, 255, 255, 0};
  FUZZ_CHECK(writePng((dir.path() / "texture.png").string(), texture).ok(), "texture.png");
}

}  // namespace mfr::fuzz
