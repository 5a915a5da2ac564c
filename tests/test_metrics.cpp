// Image metrics: MSE and PSNR against values computed by hand, and LDR-FLIP against (a) a
// closed-form evaluation of the pipeline for uniform images, (b) an independent double-precision
// implementation written here from the paper's description (direct 2D convolutions, colour
// matrices derived from the sRGB primaries), and (c) pinned values. The CLI's error cases run the
// real binary.
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_runner.hpp"
#include "mfr/core/image.hpp"
#include "mfr/metrics/flip.hpp"
#include "mfr/metrics/image_metrics.hpp"
#include "mfr/metrics/magma.hpp"

namespace {

using namespace mfr;

Image8 makeImage(int w, int h, const std::vector<std::array<uint8_t, 3>>& pixels) {
  Image8 im;
  im.width = w;
  im.height = h;
  im.rgba.resize(static_cast<size_t>(w) * h * 4);
  for (size_t i = 0; i < pixels.size(); ++i) {
    im.rgba[i * 4 + 0] = pixels[i][0];
    im.rgba[i * 4 + 1] = pixels[i][1];
    im.rgba[i * 4 + 2] = pixels[i][2];
    im.rgba[i * 4 + 3] = 255;
  }
  return im;
}

template <typename F>
Image8 generate(int w, int h, F&& f) {
  std::vector<std::array<uint8_t, 3>> p;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) p.push_back(f(x, y));
  return makeImage(w, h, p);
}

Image8 uniform(int w, int h, uint8_t r, uint8_t g, uint8_t b) {
  return generate(w, h, [&](int, int) { return std::array<uint8_t, 3>{r, g, b}; });
}

// deterministic pseudo-random bytes
uint8_t hashByte(uint32_t x) {
  x ^= x >> 16;
  x *= 0x7feb352dU;
  x ^= x >> 15;
  x *= 0x846ca68bU;
  x ^= x >> 16;
  return static_cast<uint8_t>(x & 0xffu);
}

// ----------------------------------------------------------------------------------------------
// MSE / PSNR
// ----------------------------------------------------------------------------------------------

double srgbDecode(double s) {
  return s <= 0.04045 ? s / 12.92 : std::pow((s + 0.055) / 1.055, 2.4);
}

TEST(ImageMetrics, IdenticalImagesHaveZeroErrorAndInfinitePsnr) {
  const Image8 a = generate(7, 5, [](int x, int y) {
    return std::array<uint8_t, 3>{hashByte(x * 31 + y), hashByte(x + 100 * y), hashByte(x * y + 7)};
  });
  auto s = compareImages(a, a);
  ASSERT_TRUE(s.ok()) << s.error().message;
  EXPECT_EQ(s->mseLinear, 0.0);
  EXPECT_EQ(s->mseSrgb, 0.0);
  EXPECT_TRUE(std::isinf(s->psnrLinear) && s->psnrLinear > 0);
  EXPECT_TRUE(std::isinf(s->psnrSrgb) && s->psnrSrgb > 0);
  EXPECT_EQ(psnrFromMse(0.0), std::numeric_limits<double>::infinity());
}

TEST(ImageMetrics, HandComputedPairs) {
  // One channel of one of two pixels goes 0 -> 255: squared error 1 in one of six values.
  const Image8 ref = makeImage(2, 1, {{0, 0, 0}, {255, 255, 255}});
  const Image8 tst = makeImage(2, 1, {{255, 0, 0}, {255, 255, 255}});
  auto s = compareImages(ref, tst);
  ASSERT_TRUE(s.ok());
  EXPECT_NEAR(s->mseSrgb, 1.0 / 6.0, 1e-15);
  EXPECT_NEAR(s->mseLinear, 1.0 / 6.0, 1e-7);
  EXPECT_NEAR(s->psnrSrgb, 7.781512503836436, 1e-12);  // 10 log10(6)

  // Grey 128 vs black: sRGB error 128/255 per channel, linear error decode(128/255).
  const Image8 grey = uniform(3, 2, 128, 128, 128), black = uniform(3, 2, 0, 0, 0);
  auto g = compareImages(grey, black);
  ASSERT_TRUE(g.ok());
  const double es = 128.0 / 255.0, el = srgbDecode(128.0 / 255.0);  // 0.2158605...
  EXPECT_NEAR(g->mseSrgb, es * es, 1e-15);
  EXPECT_NEAR(g->mseLinear, el * el, 1e-7);
  EXPECT_NEAR(g->psnrSrgb, -10.0 * std::log10(es * es), 1e-12);   // 5.9859 dB
  EXPECT_NEAR(g->psnrLinear, -10.0 * std::log10(el * el), 1e-5);  // 13.3165 dB
  EXPECT_NEAR(g->psnrLinear, 13.3165, 1e-4);

  // Single-space helpers agree with compareImages; channels are averaged.
  const Image8 red = uniform(1, 1, 255, 0, 0), cyan = uniform(1, 1, 0, 255, 255);
  EXPECT_NEAR(*meanSquaredError(red, cyan, MetricSpace::Srgb), 1.0, 1e-15);
  EXPECT_NEAR(*meanSquaredError(red, uniform(1, 1, 0, 0, 0), MetricSpace::Linear), 1.0 / 3.0, 1e-7);
}

TEST(ImageMetrics, ErrorMapIsPerPixelMeanOverChannels) {
  const Image8 ref = makeImage(2, 2, {{0, 0, 0}, {255, 255, 255}, {10, 20, 30}, {0, 0, 0}});
  const Image8 tst = makeImage(2, 2, {{255, 0, 0}, {255, 255, 255}, {10, 20, 30}, {255, 255, 255}});
  auto m = squaredErrorMap(ref, tst, MetricSpace::Srgb);
  ASSERT_TRUE(m.ok());
  ASSERT_EQ(m->values.size(), 4u);
  EXPECT_NEAR(m->values[0], 1.0f / 3.0f, 1e-7);
  EXPECT_EQ(m->values[1], 0.0f);
  EXPECT_EQ(m->values[2], 0.0f);
  EXPECT_NEAR(m->values[3], 1.0f, 1e-7);
  EXPECT_FLOAT_EQ(m->maxValue(), 1.0f);
  for (float v : m->values) EXPECT_TRUE(v >= 0.0f && v <= 1.0f);
  // colour-mapped: scaled to its maximum, magma's ends
  const Image8 im = errorMapImage(*m);
  ASSERT_EQ(im.width, 2);
  ASSERT_EQ(im.height, 2);
  const auto lo = magma8(0), hi = magma8(255);
  EXPECT_EQ(im.rgba[4 + 0], lo[0]);
  EXPECT_EQ(im.rgba[4 + 2], lo[2]);
  EXPECT_EQ(im.rgba[12 + 0], hi[0]);
  EXPECT_EQ(im.rgba[12 + 1], hi[1]);
  EXPECT_EQ(im.rgba[12 + 3], 255);
}

TEST(ImageMetrics, SizeMismatchIsAnErrorNamingBothSizes) {
  const Image8 a = uniform(3, 2, 0, 0, 0), b = uniform(2, 3, 0, 0, 0);
  auto s = compareImages(a, b);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().message.find("3x2"), std::string::npos) << s.error().message;
  EXPECT_NE(s.error().message.find("2x3"), std::string::npos) << s.error().message;
  EXPECT_FALSE(squaredErrorMap(a, b, MetricSpace::Linear).ok());
  auto f = computeFlip(a, b);
  ASSERT_FALSE(f.ok());
  EXPECT_NE(f.error().message.find("3x2"), std::string::npos) << f.error().message;
  EXPECT_NE(f.error().message.find("2x3"), std::string::npos) << f.error().message;
}

TEST(ImageMetrics, NonFiniteLinearValuesAreAnErrorNamingTheImageAndThePixel) {
  ImageRGB image(4, 3, glm::vec3(0.25f));
  EXPECT_TRUE(checkFinite(image, "reference").ok());
  image.at(2, 1).g = std::numeric_limits<float>::quiet_NaN();
  image.at(3, 2).r = std::numeric_limits<float>::infinity();  // later in row order
  auto bad = checkFinite(image, "reference");
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().message,
            "reference: pixel (2, 1) is not finite (nan in g): the image must hold finite values");
  image.at(2, 1).g = 0.0f;
  image.at(3, 2).r = -std::numeric_limits<float>::infinity();
  EXPECT_EQ(checkFinite(image, "test").error().message,
            "test: pixel (3, 2) is not finite (-inf in r): the image must hold finite values");
  // an all-NaN image against black: an error, never MSE 0 and PSNR inf
  ImageRGB nan(2, 2, glm::vec3(std::numeric_limits<float>::quiet_NaN()));
  EXPECT_EQ(checkFinite(nan, "test").error().message,
            "test: pixel (0, 0) is not finite (nan in r): the image must hold finite values");
}

TEST(ImageMetrics, MagmaTableMatchesMatplotlib) {
  // spot checks of matplotlib's magma (first, middle, last entries)
  const auto& t = magmaTable();
  EXPECT_FLOAT_EQ(t[0][0], 0.001462f);
  EXPECT_FLOAT_EQ(t[0][2], 0.013866f);
  EXPECT_FLOAT_EQ(t[128][0], 0.716387f);
  EXPECT_FLOAT_EQ(t[128][1], 0.214982f);
  EXPECT_FLOAT_EQ(t[128][2], 0.475290f);
  EXPECT_FLOAT_EQ(t[255][0], 0.987053f);
  EXPECT_FLOAT_EQ(t[255][1], 0.991438f);
  EXPECT_FLOAT_EQ(t[255][2], 0.749504f);
  EXPECT_EQ(magmaIndex(0.0f), 0);
  EXPECT_EQ(magmaIndex(1.0f), 255);
  EXPECT_EQ(magmaIndex(0.5f), 128);  // round(127.5)
  EXPECT_EQ(magmaIndex(std::nanf("")), 0);
  EXPECT_EQ(magma8(255), (std::array<uint8_t, 3>{252, 253, 191}));
  EXPECT_EQ(magma8(0), (std::array<uint8_t, 3>{0, 0, 4}));
}

// ----------------------------------------------------------------------------------------------
// FLIP: an independent double-precision reference, written from the paper's description
// ----------------------------------------------------------------------------------------------

namespace ref {

constexpr double kPi = 3.14159265358979323846;
using M3 = std::array<std::array<double, 3>, 3>;
using V3 = std::array<double, 3>;

V3 mul(const M3& m, const V3& v) {
  return {m[0][0] * v[0] + m[0][1] * v[1] + m[0][2] * v[2],
          m[1][0] * v[0] + m[1][1] * v[1] + m[1][2] * v[2],
          m[2][0] * v[0] + m[2][1] * v[1] + m[2][2] * v[2]};
}

M3 inverse(const M3& m) {
  const double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                     m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                     m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
  M3 r;
  r[0][0] = (m[1][1] * m[2][2] - m[1][2] * m[2][1]) / det;
  r[0][1] = (m[0][2] * m[2][1] - m[0][1] * m[2][2]) / det;
  r[0][2] = (m[0][1] * m[1][2] - m[0][2] * m[1][1]) / det;
  r[1][0] = (m[1][2] * m[2][0] - m[1][0] * m[2][2]) / det;
  r[1][1] = (m[0][0] * m[2][2] - m[0][2] * m[2][0]) / det;
  r[1][2] = (m[0][2] * m[1][0] - m[0][0] * m[1][2]) / det;
  r[2][0] = (m[1][0] * m[2][1] - m[1][1] * m[2][0]) / det;
  r[2][1] = (m[0][1] * m[2][0] - m[0][0] * m[2][1]) / det;
  r[2][2] = (m[0][0] * m[1][1] - m[0][1] * m[1][0]) / det;
  return r;
}

// linear sRGB -> XYZ from the primaries' and D65's chromaticities (IEC 61966-2-1)
M3 rgbToXyz() {
  const double xy[3][2] = {{0.64, 0.33}, {0.30, 0.60}, {0.15, 0.06}};
  const double wx = 0.3127, wy = 0.3290;
  M3 p;
  for (int c = 0; c < 3; ++c) {
    p[0][c] = xy[c][0] / xy[c][1];
    p[1][c] = 1.0;
    p[2][c] = (1.0 - xy[c][0] - xy[c][1]) / xy[c][1];
  }
  const V3 s = mul(inverse(p), V3{wx / wy, 1.0, (1.0 - wx - wy) / wy});
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) p[r][c] *= s[c];
  return p;
}

struct Space {
  M3 toXyz = rgbToXyz();
  M3 toRgb = inverse(toXyz);
  V3 white = mul(toXyz, V3{1.0, 1.0, 1.0});

  V3 lab(const V3& rgb) const {
    const V3 xyz = mul(toXyz, rgb);
    const double d = 6.0 / 29.0;
    auto f = [&](double t) { return t > d * d * d ? std::cbrt(t) : t / (3 * d * d) + 4.0 / 29.0; };
    const double fx = f(xyz[0] / white[0]), fy = f(xyz[1] / white[1]), fz = f(xyz[2] / white[2]);
    return {116 * fy - 16, 500 * (fx - fy), 200 * (fy - fz)};
  }
  V3 hunt(const V3& lab) const { return {lab[0], 0.01 * lab[0] * lab[1], 0.01 * lab[0] * lab[2]}; }
  static double hyab(const V3& a, const V3& b) {
    return std::abs(a[0] - b[0]) + std::hypot(a[1] - b[1], a[2] - b[2]);
  }
  double cmax() const { return std::pow(hyab(hunt(lab({0, 1, 0})), hunt(lab({0, 0, 1}))), 0.7); }
  // HyAB^qc remapped to [0, 1] with the (pc, pt) knee
  double remap(double e) const {
    const double cm = cmax(), knee = 0.4 * cm;
    return e < knee ? e * 0.95 / knee : 0.95 + (e - knee) / (cm - knee) * 0.05;
  }
};

struct Plane {
  int w, h;
  std::vector<double> v;
  double at(int x, int y) const {
    return v[static_cast<size_t>(std::clamp(y, 0, h - 1)) * w + std::clamp(x, 0, w - 1)];
  }
};

// 2D convolution with a (2r+1)^2 kernel, clamp-to-edge
Plane convolve(const Plane& p, const std::vector<double>& k, int r) {
  Plane out{p.w, p.h, std::vector<double>(p.v.size())};
  const int n = 2 * r + 1;
  for (int y = 0; y < p.h; ++y)
    for (int x = 0; x < p.w; ++x) {
      double s = 0;
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i)
          s += k[static_cast<size_t>(j) * n + i] * p.at(x + i - r, y + j - r);
      out.v[static_cast<size_t>(y) * p.w + x] = s;
    }
  return out;
}

struct Flip {
  std::vector<double> map, colorOnly;
  double mean = 0, colorOnlyMean = 0;
};

Flip flip(const Image8& a, const Image8& b, double ppd = 0.7 * 3840.0 / 0.7 * kPi / 180.0) {
  const Space sp;
  const int w = a.width, h = a.height;
  const size_t n = static_cast<size_t>(w) * h;
  // CSF kernels: sum_i a_i sqrt(pi / b_i) exp(-pi^2 r^2 / b_i), r in degrees, normalised in 2D
  const double A1[3] = {1, 1, 34.1}, B1[3] = {0.0047, 0.0053, 0.04}, A2[3] = {0, 0, 13.5},
               B2[3] = {1e-5, 1e-5, 0.025};
  const int rs = static_cast<int>(std::ceil(3 * std::sqrt(0.04 / (2 * kPi * kPi)) * ppd));
  std::vector<double> csf[3];
  for (int c = 0; c < 3; ++c) {
    double sum = 0;
    for (int j = -rs; j <= rs; ++j)
      for (int i = -rs; i <= rs; ++i) {
        const double r2 = (i * i + j * j) / (ppd * ppd);
        double g = A1[c] * std::sqrt(kPi / B1[c]) * std::exp(-kPi * kPi * r2 / B1[c]);
        if (A2[c] != 0) g += A2[c] * std::sqrt(kPi / B2[c]) * std::exp(-kPi * kPi * r2 / B2[c]);
        csf[c].push_back(g);
        sum += g;
      }
    for (double& g : csf[c]) g /= sum;
  }
  // feature kernels from 1D Gaussian derivatives, lobes normalised separately
  const double sigma = 0.5 * 0.082 * ppd;
  const int rf = static_cast<int>(std::ceil(3 * sigma));
  std::vector<double> g, dg, ddg;
  double gs = 0, dp = 0, dn = 0, ddp = 0, ddn = 0;
  for (int i = -rf; i <= rf; ++i) {
    const double e = std::exp(-i * i / (2 * sigma * sigma));
    g.push_back(e);
    dg.push_back(-i * e);
    ddg.push_back((i * i / (sigma * sigma) - 1) * e);
    gs += e;
    (dg.back() > 0 ? dp : dn) += std::abs(dg.back());
    (ddg.back() > 0 ? ddp : ddn) += std::abs(ddg.back());
  }
  for (size_t i = 0; i < g.size(); ++i) {
    g[i] /= gs;
    dg[i] /= dg[i] > 0 ? dp : dn;
    ddg[i] /= ddg[i] > 0 ? ddp : ddn;
  }
  const int nf = 2 * rf + 1;
  std::vector<double> ex, ey, px, py;  // d/dx, d/dy, d2/dx2, d2/dy2 (row-major j, i)
  for (int j = 0; j < nf; ++j)
    for (int i = 0; i < nf; ++i) {
      ex.push_back(dg[i] * g[j]);
      ey.push_back(g[i] * dg[j]);
      px.push_back(ddg[i] * g[j]);
      py.push_back(g[i] * ddg[j]);
    }

  std::vector<V3> lab[2];
  std::vector<double> edge[2], point[2];
  const Image8* im[2] = {&a, &b};
  for (int k = 0; k < 2; ++k) {
    Plane ch[3] = {{w, h, std::vector<double>(n)},
                   {w, h, std::vector<double>(n)},
                   {w, h, std::vector<double>(n)}};
    Plane lum{w, h, std::vector<double>(n)};
    for (size_t i = 0; i < n; ++i) {
      const V3 rgb = {srgbDecode(im[k]->rgba[i * 4] / 255.0),
                      srgbDecode(im[k]->rgba[i * 4 + 1] / 255.0),
                      srgbDecode(im[k]->rgba[i * 4 + 2] / 255.0)};
      const V3 xyz = mul(sp.toXyz, rgb);
      const double X = xyz[0] / sp.white[0], Y = xyz[1] / sp.white[1], Z = xyz[2] / sp.white[2];
      ch[0].v[i] = 116 * Y - 16;  // YCxCz
      ch[1].v[i] = 500 * (X - Y);
      ch[2].v[i] = 200 * (Y - Z);
      lum.v[i] = Y;  // (Y_YCxCz + 16) / 116
    }
    Plane f[3];
    for (int c = 0; c < 3; ++c) f[c] = convolve(ch[c], csf[c], rs);
    for (size_t i = 0; i < n; ++i) {
      const double Y = (f[0].v[i] + 16) / 116;
      const V3 xyz = {(Y + f[1].v[i] / 500) * sp.white[0], Y * sp.white[1],
                      (Y - f[2].v[i] / 200) * sp.white[2]};
      V3 rgb = mul(sp.toRgb, xyz);
      for (double& c : rgb) c = std::clamp(c, 0.0, 1.0);
      lab[k].push_back(sp.hunt(sp.lab(rgb)));
    }
    const Plane dx = convolve(lum, ex, rf), dy = convolve(lum, ey, rf);
    const Plane ddx = convolve(lum, px, rf), ddy = convolve(lum, py, rf);
    for (size_t i = 0; i < n; ++i) {
      edge[k].push_back(std::hypot(dx.v[i], dy.v[i]));
      point[k].push_back(std::hypot(ddx.v[i], ddy.v[i]));
    }
  }
  Flip r;
  for (size_t i = 0; i < n; ++i) {
    const double cd = sp.remap(std::pow(Space::hyab(lab[0][i], lab[1][i]), 0.7));
    const double fd =
        std::sqrt(std::max(std::abs(edge[0][i] - edge[1][i]), std::abs(point[0][i] - point[1][i])) /
                  std::sqrt(2.0));
    r.map.push_back(std::pow(cd, 1 - fd));
    r.colorOnly.push_back(cd);
    r.mean += r.map.back() / n;
    r.colorOnlyMean += cd / n;
  }
  return r;
}

}  // namespace ref

// The optimised float implementation against the independent double one.
void expectMatchesReference(const Image8& a, const Image8& b, double meanTol = 2e-5,
                            double pixelTol = 2e-4) {
  auto f = computeFlip(a, b);
  ASSERT_TRUE(f.ok()) << f.error().message;
  const ref::Flip r = ref::flip(a, b);
  EXPECT_NEAR(f->mean, r.mean, meanTol);
  ASSERT_EQ(f->errorMap.size(), r.map.size());
  double worst = 0;
  for (size_t i = 0; i < r.map.size(); ++i)
    worst = std::max(worst, std::abs(f->errorMap[i] - r.map[i]));
  EXPECT_LT(worst, pixelTol);
}

// sRGB code for a linear value (nearest), for building test images
uint8_t code(double linear) {
  int best = 0;
  for (int c = 1; c < 256; ++c)
    if (std::abs(srgbDecode(c / 255.0) - linear) < std::abs(srgbDecode(best / 255.0) - linear))
      best = c;
  return static_cast<uint8_t>(best);
}

Image8 checkerboard(int w, int h, int cell) {
  return generate(w, h, [&](int x, int y) {
    const uint8_t v = ((x / cell + y / cell) % 2) ? 255 : 0;
    return std::array<uint8_t, 3>{v, v, v};
  });
}

Image8 colourPattern(int w, int h, int shift) {
  return generate(w, h, [&](int x, int y) {
    const int r = std::clamp(40 + 5 * x + shift, 0, 255), g = std::clamp(200 - 4 * y, 0, 255),
              b = std::clamp(90 + 3 * (x + y) - shift, 0, 255);
    return std::array<uint8_t, 3>{static_cast<uint8_t>(r), static_cast<uint8_t>(g),
                                  static_cast<uint8_t>(b)};
  });
}

Image8 noise(int w, int h, uint32_t seed) {
  return generate(w, h, [&](int x, int y) {
    const uint32_t i = static_cast<uint32_t>(y * w + x) * 3 + seed * 7919;
    return std::array<uint8_t, 3>{hashByte(i), hashByte(i + 1), hashByte(i + 2)};
  });
}

TEST(Flip, DefaultPixelsPerDegree) {
  EXPECT_NEAR(kFlipDefaultPixelsPerDegree, 67.0206432766, 1e-9);
}

TEST(Flip, IdenticalImagesGiveZero) {
  for (const Image8& a : {uniform(5, 4, 30, 60, 90), checkerboard(19, 13, 1), noise(23, 17, 3)}) {
    auto f = computeFlip(a, a);
    ASSERT_TRUE(f.ok());
    EXPECT_EQ(f->mean, 0.0);
    for (float e : f->errorMap) EXPECT_EQ(e, 0.0f);
  }
}

// Uniform black against uniform white, evaluated through the pipeline by hand: filters preserve a
// constant and give no edge or point response, so FLIP is the remapped HyAB distance between
// black (L = 0) and white (L = 100): 0.95 + (100^0.7 - pc cmax) / (cmax - pc cmax) * (1 - 0.95).
TEST(Flip, BlackVersusWhiteMatchesTheClosedForm) {
  const ref::Space sp;
  const ref::V3 green = sp.hunt(sp.lab({0, 1, 0})), blue = sp.hunt(sp.lab({0, 0, 1}));
  // CIELAB of the sRGB primaries (textbook values)
  EXPECT_NEAR(sp.lab({0, 1, 0})[0], 87.735, 2e-3);
  EXPECT_NEAR(sp.lab({0, 1, 0})[1], -86.183, 2e-3);
  EXPECT_NEAR(sp.lab({0, 0, 1})[2], -107.86, 2e-2);
  const double cmax = std::pow(ref::Space::hyab(green, blue), 0.7);
  EXPECT_NEAR(cmax, 41.2766, 1e-3);
  const double hyab = std::pow(100.0, 0.7);
  const double expected = 0.95 + (hyab - 0.4 * cmax) / (cmax - 0.4 * cmax) * 0.05;
  EXPECT_NEAR(expected, 0.967379, 1e-6);

  const Image8 black = uniform(16, 12, 0, 0, 0), white = uniform(16, 12, 255, 255, 255);
  auto f = computeFlip(black, white);
  ASSERT_TRUE(f.ok());
  EXPECT_NEAR(f->mean, expected, 2e-5);
  for (float e : f->errorMap) EXPECT_NEAR(e, expected, 2e-5);
  EXPECT_NEAR(f->mean, 0.9673883, 1e-6);  // pinned

  // Uniform colours below the knee: grey 50% against grey 60% linear, by hand. In float the
  // derivative filters leave ~1e-8 of a constant image (their lobes cancel only to rounding), which
  // the feature exponent qf = 1/2 lifts to ~1e-4, hence the looser tolerance (the FLIP tool, also
  // float, does the same).
  const uint8_t g1 = code(0.5), g2 = code(0.6);
  const double l1 =
      sp.lab({srgbDecode(g1 / 255.0), srgbDecode(g1 / 255.0), srgbDecode(g1 / 255.0)})[0];
  const double l2 =
      sp.lab({srgbDecode(g2 / 255.0), srgbDecode(g2 / 255.0), srgbDecode(g2 / 255.0)})[0];
  const double small = std::pow(std::abs(l1 - l2), 0.7) * 0.95 / (0.4 * cmax);
  auto s = computeFlip(uniform(9, 9, g1, g1, g1), uniform(9, 9, g2, g2, g2));
  ASSERT_TRUE(s.ok());
  EXPECT_NEAR(s->mean, small, 1e-4);
  EXPECT_NEAR(small, 0.188307, 1e-6);
  EXPECT_NEAR(s->mean, 0.1883559, 1e-6);  // pinned
}

TEST(Flip, CheckerboardVersusFlatGreyNeedsTheFeatureTerm) {
  // 1-pixel checkerboard of black and white against the grey of its mean linear value: the CSF
  // blurs the checkerboard to nearly that grey, so the error comes from the feature term.
  const uint8_t grey = code(0.5);
  const Image8 board = checkerboard(24, 20, 1), flat = uniform(24, 20, grey, grey, grey);
  expectMatchesReference(board, flat);
  const ref::Flip r = ref::flip(board, flat);
  auto f = computeFlip(board, flat);
  ASSERT_TRUE(f.ok());
  EXPECT_GT(f->mean, 1.5 * r.colorOnlyMean);  // features raise the error well above colour alone
  EXPECT_NEAR(f->mean, 0.0355232, 1e-6);      // pinned

  // 4-pixel cells: strong edges
  const Image8 coarse = checkerboard(24, 20, 4);
  expectMatchesReference(coarse, flat);
  auto c = computeFlip(coarse, flat);
  ASSERT_TRUE(c.ok());
  EXPECT_NEAR(c->mean, 0.5282904, 1e-6);  // pinned
}

TEST(Flip, ColourShiftMatchesTheIndependentImplementation) {
  const Image8 a = colourPattern(37, 23, 0), b = colourPattern(37, 23, 40);
  expectMatchesReference(a, b);
  auto f = computeFlip(a, b);
  ASSERT_TRUE(f.ok());
  EXPECT_NEAR(f->mean, 0.4647518, 1e-6);  // pinned
}

TEST(Flip, NoiseOfOddSizesMatchesTheIndependentImplementation) {
  // sizes smaller than the filters and not multiples of anything: borders everywhere
  for (auto [w, h] : std::vector<std::pair<int, int>>{{31, 17}, {1, 1}, {3, 29}, {13, 2}}) {
    SCOPED_TRACE(std::to_string(w) + "x" + std::to_string(h));
    expectMatchesReference(noise(w, h, 1), noise(w, h, 2));
  }
  auto f = computeFlip(noise(31, 17, 1), noise(31, 17, 2));
  ASSERT_TRUE(f.ok());
  EXPECT_NEAR(f->mean, 0.4570386, 1e-6);  // pinned
}

TEST(Flip, IsSymmetricAndInRange) {
  // LDR-FLIP treats both images alike (HyAB and the feature differences are symmetric); only
  // HDR-FLIP, which picks exposures from the reference, is not.
  const Image8 a = colourPattern(29, 21, 0), b = noise(29, 21, 5);
  auto ab = computeFlip(a, b), ba = computeFlip(b, a);
  ASSERT_TRUE(ab.ok() && ba.ok());
  EXPECT_EQ(ab->mean, ba->mean);
  EXPECT_EQ(ab->errorMap, ba->errorMap);
  for (float e : ab->errorMap) EXPECT_TRUE(e >= 0.0f && e <= 1.0f) << e;
}

TEST(Flip, ResultDoesNotDependOnThreadCount) {
  const Image8 a = noise(97, 61, 11), b = colourPattern(97, 61, 25);
  Result<FlipResult> one = Error{}, two = Error{};
  tbb::task_arena(1).execute([&] { one = computeFlip(a, b); });
  tbb::task_arena(2).execute([&] { two = computeFlip(a, b); });
  ASSERT_TRUE(one.ok() && two.ok());
  EXPECT_EQ(one->mean, two->mean);
  EXPECT_EQ(one->errorMap, two->errorMap);
}

TEST(Flip, PixelsPerDegreeChangesTheFilters) {
  const Image8 board = checkerboard(20, 20, 2), grey = uniform(20, 20, 128, 128, 128);
  auto near = computeFlip(board, grey, 10.0), far = computeFlip(board, grey, 200.0);
  ASSERT_TRUE(near.ok() && far.ok());
  EXPECT_NE(near->mean, far->mean);
  EXPECT_FALSE(computeFlip(board, grey, 0.0).ok());
  EXPECT_FALSE(computeFlip(board, grey, std::nan("")).ok());
  Image8 empty;
  EXPECT_FALSE(computeFlip(empty, empty).ok());
}

TEST(Flip, ErrorImageUsesMagma) {
  auto f = computeFlip(uniform(4, 3, 0, 0, 0), uniform(4, 3, 255, 255, 255));
  ASSERT_TRUE(f.ok());
  const Image8 im = flipErrorImage(*f);
  ASSERT_EQ(im.width, 4);
  ASSERT_EQ(im.height, 3);
  const auto c = magma8(magmaIndex(static_cast<float>(f->mean)));  // index 247
  EXPECT_EQ(magmaIndex(static_cast<float>(f->mean)), 247);
  for (int i = 0; i < 12; ++i) {
    EXPECT_EQ(im.rgba[i * 4 + 0], c[0]);
    EXPECT_EQ(im.rgba[i * 4 + 1], c[1]);
    EXPECT_EQ(im.rgba[i * 4 + 2], c[2]);
    EXPECT_EQ(im.rgba[i * 4 + 3], 255);
  }
  EXPECT_EQ(flipPercentile(*f, 0.0), flipPercentile(*f, 1.0));
}

TEST(Flip, Percentiles) {
  FlipResult r;
  r.width = 5;
  r.height = 1;
  r.errorMap = {0.5f, 0.1f, 0.9f, 0.3f, 0.7f};
  EXPECT_FLOAT_EQ(flipPercentile(r, 0.0), 0.1f);
  EXPECT_FLOAT_EQ(flipPercentile(r, 0.5), 0.5f);
  EXPECT_FLOAT_EQ(flipPercentile(r, 0.95), 0.9f);
  EXPECT_FLOAT_EQ(flipPercentile(r, 1.0), 0.9f);
}

// ----------------------------------------------------------------------------------------------
// CLI
// ----------------------------------------------------------------------------------------------

namespace fs = std::filesystem;

using MetricsCliRun = mfr::test::CliRun;

fs::path metricsTempDir() {
  static const fs::path dir = mfr::test::processTempDir("mfr_metrics_test");
  return dir;
}

MetricsCliRun runMetricsCli(const std::string& args) {
  std::string command = "metrics ";
  command += args;
  return mfr::test::runCli(command, metricsTempDir());
}

std::string writeImage(const std::string& name, const Image8& image) {
  const fs::path p = metricsTempDir() / name;
  EXPECT_TRUE(writePng(p.string(), image).ok());
  return p.string();
}

void expectMetricsFailure(const std::string& args, const std::vector<std::string>& needles) {
  const MetricsCliRun r = runMetricsCli(args);
  EXPECT_FALSE(r.signaled) << args;
  EXPECT_EQ(r.exitCode, 1) << args << "\n" << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << "\n" << r.err;
  for (const std::string& needle : needles)
    EXPECT_NE(r.err.find(needle), std::string::npos) << args << "\n" << r.err;
}

TEST(MetricsCli, BadInputsAreOneLineErrorsNamingTheInput) {
  const std::string good = writeImage("good.png", noise(8, 6, 1));
  const std::string other = writeImage("other.png", noise(6, 8, 2));
  const fs::path garbage = metricsTempDir() / "garbage.png";
  std::ofstream(garbage, std::ios::binary) << "this is not a PNG";
  expectMetricsFailure("/nonexistent/ref.png " + good, {"/nonexistent/ref.png"});
  expectMetricsFailure(good + " /nonexistent/test.png", {"/nonexistent/test.png"});
  expectMetricsFailure(garbage.string() + " " + good, {garbage.string()});
  expectMetricsFailure(good + " " + other, {good, other, "8x6", "6x8"});
  expectMetricsFailure(good, {"two images"});
  expectMetricsFailure(good + " " + good + " --ppd -3", {"--ppd"});
  expectMetricsFailure(good + " " + good + " --flip-map /proc/nope/map.png",
                       {"/proc/nope/map.png"});
}

TEST(MetricsCli, IdenticalImagesJson) {
  const std::string a = writeImage("same.png", colourPattern(12, 9, 0));
  const MetricsCliRun r = runMetricsCli(a + " " + a + " --json");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  for (const char* key : {"reference", "test", "width", "height", "mse_linear", "mse_srgb",
                          "psnr_linear", "psnr_srgb", "flip_mean"})
    EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_EQ(j["width"], 12);
  EXPECT_EQ(j["height"], 9);
  EXPECT_EQ(j["mse_linear"].get<double>(), 0.0);
  EXPECT_EQ(j["mse_srgb"].get<double>(), 0.0);
  EXPECT_TRUE(j["psnr_linear"].is_null());  // +inf
  EXPECT_TRUE(j["psnr_srgb"].is_null());
  EXPECT_EQ(j["flip_mean"].get<double>(), 0.0);
}

TEST(MetricsCli, WritesMapsAndAgreesWithTheLibrary) {
  const Image8 ia = checkerboard(20, 14, 2), ib = colourPattern(20, 14, 30);
  const std::string a = writeImage("a.png", ia), b = writeImage("b.png", ib);
  const fs::path flipMap = metricsTempDir() / "maps" / "flip.png";
  const fs::path errMap = metricsTempDir() / "maps" / "err.png";
  fs::remove_all(metricsTempDir() / "maps");
  const MetricsCliRun r = runMetricsCli(a + " " + b + " --json --flip-map " + flipMap.string() +
                                        " --error-map " + errMap.string());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  auto flip = computeFlip(ia, ib);
  auto stats = compareImages(ia, ib);
  ASSERT_TRUE(flip.ok() && stats.ok());
  EXPECT_DOUBLE_EQ(j["flip_mean"].get<double>(), flip->mean);
  EXPECT_DOUBLE_EQ(j["mse_srgb"].get<double>(), stats->mseSrgb);
  EXPECT_DOUBLE_EQ(j["psnr_linear"].get<double>(), stats->psnrLinear);
  auto fm = readPng(flipMap.string());
  ASSERT_TRUE(fm.ok());
  EXPECT_EQ(fm->width, 20);
  EXPECT_EQ(fm->height, 14);
  EXPECT_EQ(fm->rgba, flipErrorImage(*flip).rgba);
  auto em = readPng(errMap.string());
  ASSERT_TRUE(em.ok());
  EXPECT_EQ(em->width, 20);

  const MetricsCliRun table = runMetricsCli(a + " " + b);
  ASSERT_EQ(table.exitCode, 0) << table.err;
  EXPECT_NE(table.out.find("FLIP"), std::string::npos);
  EXPECT_NE(table.out.find("PSNR"), std::string::npos);
  const MetricsCliRun quiet = runMetricsCli(a + " " + b + " --quiet");
  EXPECT_EQ(quiet.exitCode, 0);
  EXPECT_TRUE(quiet.out.empty());
}

}  // namespace
