// The exact answer the peer-method tests compare with: each pixel's fragments as the A-buffer
// captured them, nearest first, and their front-to-back "over" composite in double.
#pragma once

#include <vector>

#include <glm/glm.hpp>

#include "mfr/core/color.hpp"
#include "mfr/method/render_output.hpp"
#include "tsan/capture_cases.hpp"

namespace mfr::test {

/// One captured fragment: depth, linear RGB and alpha.
struct AbufferFragment {
  double d;
  glm::dvec3 c;
  double a;
  bool operator==(const AbufferFragment&) const = default;
};

/// Every pixel's fragments of an A-buffer render kept with keepStores, nearest first.
inline std::vector<std::vector<AbufferFragment>> abufferFragments(const RenderOutput& abuffer) {
  std::vector<std::vector<AbufferFragment>> out;
  for (const std::vector<FragmentNode>& nodes : capturedSets(abuffer)) {
    std::vector<AbufferFragment> px;
    for (FragmentNode n : nodes) {
      const glm::vec4 c = unpackFragmentColor(nodeColor(n));
      px.push_back({nodeDepth(n), glm::dvec3(c), c.a});
    }
    out.push_back(px);
  }
  return out;
}

/// Front-to-back "over" of a pixel's fragments over `background`, in double.
inline glm::dvec3 overComposite(const std::vector<AbufferFragment>& f, glm::dvec3 background) {
  glm::dvec3 c(0.0);
  double T = 1.0;
  for (const AbufferFragment& x : f) {
    c += T * x.a * x.c;
    T *= 1.0 - x.a;
  }
  return c + T * background;
}

}  // namespace mfr::test
