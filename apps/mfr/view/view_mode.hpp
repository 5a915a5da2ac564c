// What the viewer's image area shows: the method's image or one of its maps, the ground truth, or
// an error/split view against it.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace mfr::view {

enum class ViewMode { Image, DepthComplexity, KMap, Importance, GroundTruth, FlipError, Wiper };

/// "image", "depth", "kmap", "importance", "truth", "flip", "wiper".
const char* viewModeName(ViewMode mode);
/// The label in the panel.
const char* viewModeLabel(ViewMode mode);
std::optional<ViewMode> parseViewMode(const std::string& name);
const std::vector<ViewMode>& allViewModes();

}  // namespace mfr::view
