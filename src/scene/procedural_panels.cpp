// procedural:panels — a CAD-like assembly of transparent boxes behind glass panels (issue 14
// sec. 2): the engineering / product-visualisation case, large flat overlapping layers with sharp
// edges.
//
// `boxes` closed axis-aligned boxes, one per cell of a 4 x 4 x ceil(boxes / 16) grid of unit
// cells in [-2, 2] x [0, 4] x [-depth, 0] (cells taken in random order, each box inside its
// cell with a random size in [0.3, 0.9] per axis, so boxes never touch), and in front of them
// `panels` glass panes: closed slabs 0.02 thick facing +z that span [-2.2, 2.2] x [-0.2, 4.2],
// at z = 0.3, 0.6, ... Every surface is closed, so n(p) is even; a line crosses a box or a
// slab at most twice, so n(p) <= 2 (boxes + panels); a line through the panels' face (like the
// default camera's centre ray) crosses every slab, so n(p) >= 2 panels there.
// Materials: one per box and per panel, alphas jitteredAlpha(alpha, spread).
#include <algorithm>
#include <string>
#include <vector>

#include "scene/procedural_internal.hpp"

namespace mfr::procedural {

Result<Scene> buildPanels(ParamReader& params, uint64_t seed) {
  const int64_t boxes = params.integer("boxes", 24, 0, 100'000);
  const int64_t panels = params.integer("panels", 3, 0, 1000);
  const float alpha = params.real("alpha", 0.3, 0.0, 1.0);
  const float spread = params.real("spread", 0.5, 0.0, 1.0);
  if (params.error()) return *params.error();
  if (boxes + panels == 0) return params.fail("boxes + panels must be at least 1");
  MFR_TRY(checkTriangleBudget(params, kBoxTriangles * static_cast<double>(boxes + panels)));
  Rng rng(seed);
  Scene scene;
  MeshBuilder mesh(scene);
  const int layers = static_cast<int>((boxes + 15) / 16);
  std::vector<int> cells(static_cast<size_t>(16 * layers));
  for (size_t i = 0; i < cells.size(); ++i) cells[i] = static_cast<int>(i);
  for (size_t i = cells.size(); i > 1; --i)
    std::swap(cells[i - 1], cells[rng.below(static_cast<uint32_t>(i))]);
  const float hueOffset = rng.uniform();
  for (int64_t b = 0; b < boxes; ++b) {
    const int cell = cells[static_cast<size_t>(b)];
    const glm::vec3 corner(static_cast<float>(cell % 4) - 2.0f, static_cast<float>((cell / 4) % 4),
                           -static_cast<float>(cell / 16) - 1.0f);
    glm::vec3 lo, hi;
    for (int a = 0; a < 3; ++a) {
      const float extent = rng.uniform(0.3f, 0.9f);
      const float offset = rng.uniform(0.0f, 1.0f - extent);
      lo[a] = corner[a] + offset;
      hi[a] = lo[a] + extent;
    }
    appendBox(mesh, lo, hi,
              mesh.material("box_" + std::to_string(b),
                            hsv(goldenHue(static_cast<uint32_t>(b), hueOffset), 0.6f, 0.9f),
                            jitteredAlpha(rng, alpha, spread)));
  }
  for (int64_t p = 0; p < panels; ++p) {
    const float z = 0.3f * static_cast<float>(p + 1);
    appendBox(mesh, {-2.2f, -0.2f, z}, {2.2f, 4.2f, z + 0.02f},
              mesh.material("panel_" + std::to_string(p), {0.8f, 0.9f, 1.0f},
                            jitteredAlpha(rng, alpha, spread)));
  }
  scene.defaultCamera = frameVertices(scene);
  return scene;
}

}  // namespace mfr::procedural
