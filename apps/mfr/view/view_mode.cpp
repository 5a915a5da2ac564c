#include "view_mode.hpp"

namespace mfr::view {

namespace {
struct Entry {
  ViewMode mode;
  const char* name;
  const char* label;
};
constexpr Entry kModes[] = {
    {ViewMode::Image, "image", "image"},
    {ViewMode::DepthComplexity, "depth", "depth complexity n(p)"},
    {ViewMode::KMap, "kmap", "k(p)"},
    {ViewMode::Importance, "importance", "importance I(p)"},
    {ViewMode::GroundTruth, "truth", "ground truth (A-buffer)"},
    {ViewMode::FlipError, "flip", "FLIP error vs A-buffer"},
    {ViewMode::Wiper, "wiper", "wiper: method | A-buffer"},
};
}  // namespace

const char* viewModeName(ViewMode mode) {
  for (const Entry& e : kModes)
    if (e.mode == mode) return e.name;
  return "?";
}

const char* viewModeLabel(ViewMode mode) {
  for (const Entry& e : kModes)
    if (e.mode == mode) return e.label;
  return "?";
}

std::optional<ViewMode> parseViewMode(const std::string& name) {
  for (const Entry& e : kModes)
    if (name == e.name) return e.mode;
  return std::nullopt;
}

const std::vector<ViewMode>& allViewModes() {
  static const std::vector<ViewMode> modes = [] {
    std::vector<ViewMode> m;
    for (const Entry& e : kModes) m.push_back(e.mode);
    return m;
  }();
  return modes;
}

}  // namespace mfr::view
