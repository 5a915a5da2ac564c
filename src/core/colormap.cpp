#include "mfr/core/colormap.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/draw_text.hpp"

namespace mfr {

glm::vec3 colormap(Colormap map, float t) {
  t = std::clamp(std::isfinite(t) ? t : 0.0f, 0.0f, 1.0f);
  // 6th-order polynomial fits (Matt Zucker, CC0)
  static const glm::vec3 viridis[7] = {
      {0.2777273272234177f, 0.005407344544966578f, 0.3340998053353061f},
      {0.1050930431085774f, 1.404613529898575f, 1.384590162594685f},
      {-0.3308618287255563f, 0.214847559468213f, 0.09509516302823659f},
      {-4.634230498983486f, -5.799100973351585f, -19.33244095627987f},
      {6.228269936347081f, 14.17993336680509f, 56.69055260068105f},
      {4.776384997670288f, -13.74514537774601f, -65.35303263337234f},
      {-5.435455855934631f, 4.645852612178535f, 26.3124352495832f}};
  static const glm::vec3 magma[7] = {
      {-0.002136485053939582f, -0.000749655052795221f, -0.005386127855323933f},
      {0.2516605407371642f, 0.6775232436837668f, 2.494026599312351f},
      {8.353717279216625f, -3.577719514958484f, 0.3144679030132573f},
      {-27.66873308576866f, 14.26473078096533f, -13.64921318813922f},
      {52.17613981234068f, -27.94360607168351f, 12.94416944238394f},
      {-50.76852536473588f, 29.04658282127291f, 4.23415299384598f},
      {18.65570506591883f, -11.48977351997711f, -5.601961508734096f}};
  const glm::vec3* c = map == Colormap::Viridis ? viridis : magma;
  const glm::vec3 v =
      c[0] + t * (c[1] + t * (c[2] + t * (c[3] + t * (c[4] + t * (c[5] + t * c[6])))));
  return glm::clamp(v, glm::vec3(0.0f), glm::vec3(1.0f));
}

namespace {

using detail::putPixel;
using detail::textWidth;

using detail::drawText;

std::string label(float v) {
  char buf[32];
  if (std::fabs(v - std::round(v)) < 1e-4f && std::fabs(v) < 1e7f)
    std::snprintf(buf, sizeof buf, "%.0f", v);
  else
    std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

}  // namespace

Image8 colorMapWithLegend(const std::vector<float>& values, int width, int height, float maxValue,
                          const std::string& title, Colormap map) {
  const int scale = std::max(1, width / 384);
  const int legendHeight = 40 * scale;
  Image8 img;
  img.width = width;
  img.height = height + legendHeight;
  img.rgba.assign(static_cast<size_t>(img.width) * img.height * 4, 255);
  const float inv = maxValue > 0.0f ? 1.0f / maxValue : 0.0f;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      putPixel(img, x, y, colormap(map, values[static_cast<size_t>(y) * width + x] * inv));
  // legend: title on the left, gradient bar, labels at min / mid / max
  const glm::vec3 ink(0.1f);
  const int barY = height + 4 * scale, barH = 10 * scale;
  // the title goes left of the bar when there is room for both
  const bool showTitle = textWidth(title, scale) + 8 * scale < width / 2;
  const int titleW = showTitle ? textWidth(title, scale) + 8 * scale : 0;
  if (showTitle) drawText(img, 4 * scale, barY + scale, title, scale, ink);
  const int barX0 = std::min(width - 1, titleW + 4 * scale);
  const int barX1 = std::max(barX0 + 1, width - 24 * scale);
  for (int x = barX0; x < barX1; ++x) {
    const glm::vec3 c = colormap(map, static_cast<float>(x - barX0) / (barX1 - barX0 - 1));
    for (int y = barY; y < barY + barH; ++y) putPixel(img, x, y, c);
  }
  const float marks[3] = {0.0f, 0.5f, 1.0f};
  for (float m : marks) {
    const std::string text = label(m * maxValue);
    const int cx = barX0 + static_cast<int>(m * (barX1 - barX0 - 1));
    const int tw = textWidth(text, scale) + 2 * scale;
    const int tx = std::clamp(cx - tw / 2, 0, std::max(0, width - tw));
    for (int y = barY + barH; y < barY + barH + 3 * scale; ++y) putPixel(img, cx, y, ink);
    drawText(img, tx, barY + barH + 4 * scale, text, scale, ink);
  }
  return img;
}

}  // namespace mfr
