// `mfr view`: the window, its panel and the session loop (interactive, --frames or --script).
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "../common.hpp"

namespace mfr::view {

struct ViewerArgs {
  cli::SceneOptions scene;
  std::string method = "abuffer";
  std::string budget;
  std::optional<uint32_t> k;
  std::string composite;
  int occupancyD = 0;  // 0: the preset's
  int maxPeels = 0;    // peel, dual-peel: at most this many passes (0: until none remains)
  std::string model;
  std::string mode = "image";
  int frames = 0;  // 0: interactive (until the window closes or the script ends)
  std::string screenshot;
  bool screenshotUi = false;
  std::string script;
  std::string statsJson;
  bool listMethods = false;
  std::string renderThread = "auto";  // on, off, auto (on when interactive)
};

/// Runs the viewer; the exit code (errors are one line on stderr).
int runViewer(const ViewerArgs& args);

}  // namespace mfr::view
