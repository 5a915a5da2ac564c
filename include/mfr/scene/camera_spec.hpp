// A camera given as numbers or as the command line's text "EX,EY,EZ,TX,TY,TZ[,UX,UY,UZ[,FOV]]"
// (eye, target, [up, [vertical field of view in degrees]]), checked the way RasterFrame::build
// will use it. The command line's --camera and the fuzzers (fuzz/fuzz_camera.cpp) go through here.
#pragma once

#include <span>
#include <string>
#include <string_view>

#include "mfr/core/result.hpp"
#include "mfr/scene/camera.hpp"

namespace mfr {

/// 6, 9 or 10 numbers: eye (3), target (3), [up (3), [fov]]. Every value must be finite and fit a
/// float; eye != target; up non-zero and not parallel to the view direction; fov in (0, 180).
/// Clip planes are left automatic (0). Errors are one line starting with `what` (e.g. "--camera").
Result<Camera> cameraFromNumbers(std::span<const double> numbers,
                                 const std::string& what = "camera");

/// Comma-separated numbers (spaces around each allowed), then cameraFromNumbers. A token that is
/// not a number is an error quoting it (control characters replaced by '?').
Result<Camera> parseCameraSpec(std::string_view text, const std::string& what = "camera");

}  // namespace mfr
