#include "mfr/scene/camera_spec.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>
#include <system_error>
#include <vector>

#include "mfr/core/quote.hpp"

namespace mfr {
namespace {

bool isSpace(char c) {
  return c == ' ' || c == '\t';
}

/// Length of v, computed so that it cannot overflow for any float components.
double length(const glm::dvec3& v) {
  return std::hypot(v.x, v.y, v.z);
}

}  // namespace

Result<Camera> cameraFromNumbers(std::span<const double> numbers, const std::string& what) {
  const size_t n = numbers.size();
  if (n != 6 && n != 9 && n != 10)
    return makeError(what + ": expected 6, 9 or 10 numbers (eye, target, [up, [fov]]), got " +
                     std::to_string(n));
  constexpr double kFloatMax = std::numeric_limits<float>::max();
  for (double v : numbers)
    if (!std::isfinite(v)) return makeError(what + ": values must be finite numbers");
  for (double v : numbers)
    if (std::abs(v) > kFloatMax)
      return makeError(what + ": values must fit a float (|v| < 3.4e38)");
  Camera camera;
  camera.eye = glm::vec3(numbers[0], numbers[1], numbers[2]);
  camera.target = glm::vec3(numbers[3], numbers[4], numbers[5]);
  if (n >= 9) camera.up = glm::vec3(numbers[6], numbers[7], numbers[8]);
  if (n == 10) {
    const double fov = numbers[9];
    if (!(fov > 0.0 && fov < 180.0))
      return makeError(what + ": field of view must be in (0, 180) degrees");
    camera.fovYDegrees = static_cast<float>(fov);
    if (!(camera.fovYDegrees > 0.0f && camera.fovYDegrees < 180.0f))
      return makeError(what + ": field of view must be in (0, 180) degrees");
    if (!validFovYDegrees(camera.fovYDegrees)) {
      char value[32];
      std::snprintf(value, sizeof value, "%g", fov);
      return makeError(what + ": field of view " + value + " degrees is narrower than " +
                       kMinFovText + " (" + kNarrowFovReason + ")");
    }
  }
  const glm::dvec3 view = glm::dvec3(camera.target) - glm::dvec3(camera.eye);
  if (!(length(view) > 0.0)) return makeError(what + ": eye and target must differ");
  const glm::dvec3 up(camera.up);
  // sine of the angle between up and the view direction: lookAt needs a well-defined right axis
  if (!(length(up) > 0.0) || !(length(glm::cross(view / length(view), up / length(up))) > 1e-6))
    return makeError(what + ": up must be non-zero and not parallel to the view direction");
  return camera;
}

Result<Camera> parseCameraSpec(std::string_view text, const std::string& what) {
  std::vector<double> numbers;
  size_t pos = 0;
  while (true) {
    const size_t comma = std::min(text.find(',', pos), text.size());
    std::string_view token = text.substr(pos, comma - pos);
    while (!token.empty() && isSpace(token.front())) token.remove_prefix(1);
    while (!token.empty() && isSpace(token.back())) token.remove_suffix(1);
    std::string_view digits = token;
    if (digits.size() > 1 && digits.front() == '+' && digits[1] != '-') digits.remove_prefix(1);
    double value = 0.0;
    const auto [ptr, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
    if (ec == std::errc::result_out_of_range && ptr == digits.data() + digits.size())
      return makeError(what + ": " + quoteInput(token, 40) + " is out of range (|v| < 3.4e38)");
    if (digits.empty() || ec != std::errc() || ptr != digits.data() + digits.size())
      return makeError(what + ": " + quoteInput(token, 40) + " is not a number (expected " +
                       "EX,EY,EZ,TX,TY,TZ[,UX,UY,UZ[,FOV]])");
    numbers.push_back(value);
    if (numbers.size() > 10) return cameraFromNumbers(numbers, what);  // too many: one message
    if (comma == text.size()) break;
    pos = comma + 1;
  }
  return cameraFromNumbers(numbers, what);
}

}  // namespace mfr
