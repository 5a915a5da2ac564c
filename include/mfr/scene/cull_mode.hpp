// Back-face culling (`--cull`): which faces of a scene's triangles are surfaces.
#pragma once

#include <cstdint>
#include <string>

#include "mfr/core/result.hpp"

namespace mfr {

/// Which back faces the engines cull (`--cull`). A triangle's front face is the side from which its
/// vertices a, b, c run counter-clockwise (glTF and OpenGL); the loaders keep that true in world
/// space (a glTF node transform with a negative determinant reverses the winding it stores).
enum class CullMode : uint8_t {
  Auto,  // as the file says: back faces of single-sided materials (Material::doubleSided false)
  None,  // no culling: every face is a surface (transparent geometry shows both sides)
  Back,  // every back face culled, whatever the materials say
};

/// "auto", "none", "back".
const char* toString(CullMode mode);
/// Parses toString's names; the error names the option as `name` ("--cull sideways: expected
/// auto, none or back").
Result<CullMode> parseCullMode(const std::string& text, const std::string& name);

}  // namespace mfr
