// LDR-FLIP, implemented from
//   P. Andersson, J. Nilsson, T. Akenine-Moller, M. Oskarsson, K. Astrom, M. D. Fairchild,
//   "FLIP: A Difference Evaluator for Alternating Images", Proc. ACM Comput. Graph. Interact. Tech.
//   (High-Performance Graphics) 3(2), 2020,
// and the conventions of the public FLIP tool (NVlabs/flip, v1.x), so that means agree with it:
//   - arithmetic in 32-bit floats with the tool's constants, and per-pixel filter sums taken in the
//     tool's order (tap -r .. r), so that maps agree to float rounding;
//   - separable filtering: the blue-yellow CSF is a sum of two Gaussians, filtered as two separable
//     passes whose 1D weights are normalised together so the 2D kernel sums to 1;
//   - clamp-to-edge borders for every filter, any image size;
//   - the mean is accumulated in double per row, then over rows in order, so it does not depend on
//     the thread count (the tool sums in float, which moves its printed mean by up to ~2e-5).
//
// Pipeline (per image, reference and test alike, then compared):
//   1. sRGB8 -> linear RGB (IEC 61966-2-1, threshold 0.04045) -> XYZ (D65) -> YCxCz (opponent
//      space, normalised by the D65 white).
//   2. Colour: each YCxCz channel is filtered by its contrast sensitivity function (a Gaussian
//      a sqrt(pi / b) exp(-pi^2 x^2 / b) in degrees, sampled at 1 / ppd), back to linear RGB,
//      clamped to [0, 1], to CIELAB, Hunt-adjusted (a, b scaled by 0.01 L), compared with HyAB
//      (|dL| + |d(a, b)|), raised to qc and remapped to [0, 1] with a knee at (pc cmax, pt).
//   3. Features: on luminance in [0, 1] ((Y + 16) / 116 of YCxCz), first- and second-derivative-
//      of-Gaussian filters (sigma = w ppd / 2) give edge and point strengths; the feature
//      difference is (max(|edge diff|, |point diff|) / sqrt 2)^qf.
//   4. FLIP = colour difference ^ (1 - feature difference).
#include "mfr/metrics/flip.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "mfr/core/memory_limit.hpp"
#include "mfr/metrics/magma.hpp"

namespace mfr {

namespace {

// --- Constants of the published algorithm -------------------------------------------------------

constexpr float kPi = 3.14159265358979f;
constexpr float kQc = 0.7f;   // colour difference exponent
constexpr float kPc = 0.4f;   // knee position, as a fraction of cmax
constexpr float kPt = 0.95f;  // knee value
constexpr float kW = 0.082f;  // feature filter width in degrees
constexpr float kQf = 0.5f;   // feature difference exponent

// Contrast sensitivity functions of the achromatic (Y), red-green (Cx) and blue-yellow (Cz)
// channels: a1 G(b1) + a2 G(b2); only Cz has a second Gaussian.
constexpr std::array<float, 3> kA1 = {1.0f, 1.0f, 34.1f};
constexpr std::array<float, 3> kB1 = {0.0047f, 0.0053f, 0.04f};
constexpr std::array<float, 3> kA2 = {0.0f, 0.0f, 13.5f};
constexpr std::array<float, 3> kB2 = {1.0e-5f, 1.0e-5f, 0.025f};

// D65 reference white and its inverse.
constexpr float kWhiteX = 0.950428545f, kWhiteZ = 1.088900371f;
constexpr float kInvWhiteX = 1.052156925f, kInvWhiteZ = 0.918357670f;

struct Col {
  float x, y, z;
};

// --- Colour spaces (float, the tool's formulas and constants) -----------------------------------

float srgbToLinear(float s) {
  if (s <= 0.04045f) return s / 12.92f;
  return std::pow((s + 0.055f) / 1.055f, 2.4f);
}

Col linearRgbToXyz(Col c) {
  // sRGB primaries, D65 white, as exact ratios
  const float a11 = 10135552.0f / 24577794.0f, a12 = 8788810.0f / 24577794.0f,
              a13 = 4435075.0f / 24577794.0f;
  const float a21 = 2613072.0f / 12288897.0f, a22 = 8788810.0f / 12288897.0f,
              a23 = 887015.0f / 12288897.0f;
  const float a31 = 1425312.0f / 73733382.0f, a32 = 8788810.0f / 73733382.0f,
              a33 = 70074185.0f / 73733382.0f;
  return {a11 * c.x + a12 * c.y + a13 * c.z, a21 * c.x + a22 * c.y + a23 * c.z,
          a31 * c.x + a32 * c.y + a33 * c.z};
}

Col xyzToLinearRgb(Col c) {
  return {3.241003275f * c.x + -1.537398934f * c.y + -0.498615861f * c.z,
          -0.969224334f * c.x + 1.875930071f * c.y + 0.041554224f * c.z,
          0.055639423f * c.x + -0.204011202f * c.y + 1.057148933f * c.z};
}

Col xyzToYCxCz(Col c) {
  const float x = c.x * kInvWhiteX, y = c.y * 1.0f, z = c.z * kInvWhiteZ;
  return {116.0f * y - 16.0f, 500.0f * (x - y), 200.0f * (y - z)};
}

Col yCxCzToXyz(Col c) {
  const float y = (c.x + 16.0f) / 116.0f;
  const float cx = c.y / 500.0f, cz = c.z / 200.0f;
  return {(y + cx) * kWhiteX, y * 1.0f, (y - cz) * kWhiteZ};
}

Col xyzToLab(Col c) {
  const float delta = 6.0f / 29.0f;
  const float deltaSquare = delta * delta;
  const float deltaCube = delta * deltaSquare;
  const float factor = 1.0f / (3.0f * deltaSquare);
  const float term = 4.0f / 29.0f;
  auto f = [&](float t) { return t > deltaCube ? std::pow(t, 1.0f / 3.0f) : factor * t + term; };
  const float fx = f(c.x * kInvWhiteX), fy = f(c.y * 1.0f), fz = f(c.z * kInvWhiteZ);
  return {116.0f * fy - 16.0f, 500.0f * (fx - fy), 200.0f * (fy - fz)};
}

float clamp01(float v) {
  return std::min(std::max(v, 0.0f), 1.0f);
}

// Lab with the Hunt adjustment: chroma scales with lightness (0.01 L).
Col huntLab(Col lab) {
  return {lab.x, 0.01f * lab.x * lab.y, 0.01f * lab.x * lab.z};
}

// HyAB: city-block distance in lightness plus Euclidean distance in (a, b).
float hyab(Col a, Col b) {
  const float da = a.y - b.y, db = a.z - b.z;
  return std::fabs(a.x - b.x) + std::sqrt(da * da + db * db);
}

// The largest colour difference FLIP expects: between (Hunt-adjusted) pure green and pure blue.
float maxColorDifference() {
  const Col green = huntLab(xyzToLab(linearRgbToXyz({0.0f, 1.0f, 0.0f})));
  const Col blue = huntLab(xyzToLab(linearRgbToXyz({0.0f, 0.0f, 1.0f})));
  return std::pow(hyab(green, blue), kQc);
}

// --- Filters ------------------------------------------------------------------------------------

// a sqrt(pi / b) exp(-pi^2 x^2 / b), x in degrees.
float csfGaussian(float x2, float a, float b) {
  const float piSq = kPi * kPi;
  return a * std::sqrt(kPi / b) * std::exp(-piSq * x2 / b);
}
// The square root of csfGaussian's amplitude: the 1D factor of one separable 2D term.
float csfGaussianSqrt(float x2, float a, float b) {
  const float piSq = kPi * kPi;
  return std::sqrt(a * std::sqrt(kPi / b)) * std::exp(-piSq * x2 / b);
}

struct SpatialFilters {
  int radius = 0;
  std::vector<float> y, cx, cz1, cz2;  // 1D weights, 2 radius + 1 taps each
};

SpatialFilters makeSpatialFilters(float ppd) {
  SpatialFilters f;
  const float piSq = kPi * kPi;
  const float maxB = std::max({kB1[0], kB1[1], kB1[2], kB2[0], kB2[1], kB2[2]});
  // 3 standard deviations of the widest Gaussian, in pixels
  f.radius = static_cast<int>(std::ceil(3.0f * std::sqrt(maxB / (2.0f * piSq)) * ppd));
  const int n = 2 * f.radius + 1;
  f.y.resize(n);
  f.cx.resize(n);
  f.cz1.resize(n);
  f.cz2.resize(n);
  const float deltaX = 1.0f / ppd;
  float sumY = 0.0f, sumCx = 0.0f, sumCz1 = 0.0f, sumCz2 = 0.0f;
  for (int i = 0; i < n; ++i) {
    const float x = static_cast<float>(i - f.radius) * deltaX;
    const float x2 = x * x;
    f.y[i] = csfGaussian(x2, kA1[0], kB1[0]);
    f.cx[i] = csfGaussian(x2, kA1[1], kB1[1]);
    f.cz1[i] = csfGaussianSqrt(x2, kA1[2], kB1[2]);
    f.cz2[i] = csfGaussianSqrt(x2, kA2[2], kB2[2]);
    sumY += f.y[i];
    sumCx += f.cx[i];
    sumCz1 += f.cz1[i];
    sumCz2 += f.cz2[i];
  }
  // Y and Cx: each 1D filter sums to 1. Cz: the 2D kernel g1 g1^T + g2 g2^T sums to
  // sum1^2 + sum2^2, so both 1D factors are divided by its square root.
  const float normY = 1.0f / sumY, normCx = 1.0f / sumCx;
  const float normCz = 1.0f / std::sqrt(sumCz1 * sumCz1 + sumCz2 * sumCz2);
  for (int i = 0; i < n; ++i) {
    f.y[i] *= normY;
    f.cx[i] *= normCx;
    f.cz1[i] *= normCz;
    f.cz2[i] *= normCz;
  }
  return f;
}

struct FeatureFilters {
  int radius = 0;
  std::vector<float> g, dg, ddg;  // Gaussian, first and second derivative
};

FeatureFilters makeFeatureFilters(float ppd) {
  FeatureFilters f;
  const float sigma = 0.5f * kW * ppd;
  f.radius = static_cast<int>(std::ceil(3.0f * sigma));
  const int n = 2 * f.radius + 1;
  f.g.resize(n);
  f.dg.resize(n);
  f.ddg.resize(n);
  float gSum = 0.0f, dgPos = 0.0f, dgNeg = 0.0f, ddgPos = 0.0f, ddgNeg = 0.0f;
  for (int i = 0; i < n; ++i) {
    const float x = static_cast<float>(i - f.radius);
    const float g = std::exp(-(x * x) / (2.0f * sigma * sigma));
    const float dg = -x * g;
    const float ddg = (x * x / (sigma * sigma) - 1.0f) * g;
    gSum += g;
    if (dg > 0.0f) {
      dgPos += dg;
    } else {
      dgNeg -= dg;
    }
    if (ddg > 0.0f) {
      ddgPos += ddg;
    } else {
      ddgNeg -= ddg;
    }
    f.g[i] = g;
    f.dg[i] = dg;
    f.ddg[i] = ddg;
  }
  // The Gaussian sums to 1; the positive and the negative lobes of each derivative sum to +1 and -1
  // separately (so a constant image gives no response, up to float rounding).
  for (int i = 0; i < n; ++i) {
    f.g[i] = f.g[i] / gSum;
    f.dg[i] = f.dg[i] / (f.dg[i] > 0.0f ? dgPos : dgNeg);
    f.ddg[i] = f.ddg[i] / (f.ddg[i] > 0.0f ? ddgPos : ddgNeg);
  }
  return f;
}

// --- Separable convolution helpers (clamp-to-edge) ----------------------------------------------

using Plane = std::vector<float>;

// row[clamp(i - radius)] for i in [0, width + 2 radius).
void padRow(const float* row, int width, int radius, float* padded) {
  for (int i = 0; i < radius; ++i) padded[i] = row[0];
  std::copy(row, row + width, padded + radius);
  for (int i = 0; i < radius; ++i) padded[radius + width + i] = row[width - 1];
}

// out[x] = sum_k w[k] padded[x + k], summed in tap order.
void convolveRow(const float* padded, const std::vector<float>& w, int width, float* out) {
  std::fill(out, out + width, 0.0f);
  for (size_t k = 0; k < w.size(); ++k) {
    const float wk = w[k];
    const float* src = padded + k;
    for (int x = 0; x < width; ++x) out[x] += wk * src[x];
  }
}

// out[x] = sum_k w[k] plane[clamp(y + k - radius)][x], summed in tap order.
void convolveColumn(const Plane& plane, const std::vector<float>& w, int width, int height, int y,
                    float* out) {
  const int radius = static_cast<int>(w.size() / 2);
  std::fill(out, out + width, 0.0f);
  for (size_t k = 0; k < w.size(); ++k) {
    const int yy = std::clamp(y + static_cast<int>(k) - radius, 0, height - 1);
    const float wk = w[k];
    const float* src = plane.data() + static_cast<size_t>(yy) * width;
    for (int x = 0; x < width; ++x) out[x] += wk * src[x];
  }
}

template <typename F>
void forRows(int height, F&& body) {
  tbb::parallel_for(tbb::blocked_range<int>(0, height, 8), [&](const tbb::blocked_range<int>& r) {
    for (int y = r.begin(); y != r.end(); ++y) body(y);
  });
}

struct YCxCzPlanes {
  Plane y, cx, cz;
};

// Stage 1: sRGB8 -> linear -> XYZ -> YCxCz.
YCxCzPlanes toYCxCz(const Image8& image, const std::array<float, 256>& decode) {
  const size_t n = static_cast<size_t>(image.width) * image.height;
  YCxCzPlanes p{Plane(n), Plane(n), Plane(n)};
  forRows(image.height, [&](int y) {
    for (size_t i = static_cast<size_t>(y) * image.width;
         i < static_cast<size_t>(y + 1) * image.width; ++i) {
      const uint8_t* px = &image.rgba[i * 4];
      const Col linear{clamp01(decode[px[0]]), clamp01(decode[px[1]]), clamp01(decode[px[2]])};
      const Col c = xyzToYCxCz(linearRgbToXyz(linear));
      p.y[i] = c.x;
      p.cx[i] = c.y;
      p.cz[i] = c.z;
    }
  });
  return p;
}

std::string sizeText(const Image8& image) {
  std::string s = std::to_string(image.width);
  s += "x";
  s += std::to_string(image.height);
  return s;
}

// The eight planes the filter passes write along rows and read along columns: the reference's
// four, then the test's.
using RowPlanes = std::array<Plane, 8>;

Result<void> checkFlipInputs(const Image8& reference, const Image8& test, double pixelsPerDegree) {
  if (reference.width != test.width || reference.height != test.height) {
    std::string message = "FLIP needs images of the same size: reference is ";
    message += sizeText(reference);
    message += ", test is ";
    message += sizeText(test);
    return makeError(message);
  }
  if (reference.width <= 0 || reference.height <= 0) {
    std::string message = "FLIP needs non-empty images (got ";
    message += sizeText(reference);
    message += ")";
    return makeError(message);
  }
  const size_t n = static_cast<size_t>(reference.width) * static_cast<size_t>(reference.height);
  if (reference.rgba.size() != n * 4 || test.rgba.size() != n * 4)
    return makeError("FLIP: image pixel data does not match its size");
  return checkFlipPixelsPerDegree(pixelsPerDegree);
}

// Stage 2a: spatial (CSF) filtering along rows: Y, Cx and the two Cz terms of both images
// (rows: ref Y, Cx, Cz1, Cz2, then the test's).
void spatialFilterRows(const YCxCzPlanes& ref, const YCxCzPlanes& tst, const SpatialFilters& sf,
                       int w, int h, RowPlanes& rows) {
  forRows(h, [&](int y) {
    std::vector<float> padded(static_cast<size_t>(w) + 2 * sf.radius);
    const size_t o = static_cast<size_t>(y) * w;
    const YCxCzPlanes* images[2] = {&ref, &tst};
    for (int i = 0; i < 2; ++i) {
      const YCxCzPlanes& im = *images[i];
      padRow(im.y.data() + o, w, sf.radius, padded.data());
      convolveRow(padded.data(), sf.y, w, rows[4 * i + 0].data() + o);
      padRow(im.cx.data() + o, w, sf.radius, padded.data());
      convolveRow(padded.data(), sf.cx, w, rows[4 * i + 1].data() + o);
      padRow(im.cz.data() + o, w, sf.radius, padded.data());
      convolveRow(padded.data(), sf.cz1, w, rows[4 * i + 2].data() + o);
      convolveRow(padded.data(), sf.cz2, w, rows[4 * i + 3].data() + o);
    }
  });
}

// Stage 2b: along columns, then the colour difference per pixel.
Plane colorDifference(const RowPlanes& rows, const SpatialFilters& sf, int w, int h) {
  const float cmax = maxColorDifference();
  const float pccmax = kPc * cmax;
  Plane colorDiff(static_cast<size_t>(w) * static_cast<size_t>(h));
  forRows(h, [&](int y) {
    std::vector<float> acc(static_cast<size_t>(w) * 8);
    for (int c = 0; c < 8; ++c) {
      const std::vector<float>& filter = (c % 4 == 0)   ? sf.y
                                         : (c % 4 == 1) ? sf.cx
                                         : (c % 4 == 2) ? sf.cz1
                                                        : sf.cz2;
      convolveColumn(rows[c], filter, w, h, y, acc.data() + static_cast<size_t>(c) * w);
    }
    const float* a = acc.data();
    for (int x = 0; x < w; ++x) {
      Col lab[2];
      for (int i = 0; i < 2; ++i) {
        const float* b = a + static_cast<size_t>(4 * i) * w;
        const Col filtered{b[x], b[w + x], b[2 * w + x] + b[3 * w + x]};
        const Col rgb = xyzToLinearRgb(yCxCzToXyz(filtered));
        const Col clamped{clamp01(rgb.x), clamp01(rgb.y), clamp01(rgb.z)};
        lab[i] = huntLab(xyzToLab(linearRgbToXyz(clamped)));
      }
      float d = std::pow(hyab(lab[0], lab[1]), kQc);
      // [0, pc cmax) -> [0, pt), [pc cmax, cmax] -> [pt, 1]
      if (d < pccmax) {
        d *= kPt / pccmax;
      } else {
        d = kPt + ((d - pccmax) / (cmax - pccmax)) * (1.0f - kPt);
      }
      colorDiff[static_cast<size_t>(y) * w + x] = d;
    }
  });
  return colorDiff;
}

// Stage 3a: feature filters along rows on normalised luminance: derivatives in x (dg, ddg) and
// the Gaussian (for the y derivatives of the next pass). Reuses the colour pass's planes: ref dx,
// ddx, g in rows[0..2], test's in rows[4..6].
void featureFilterRows(const YCxCzPlanes& ref, const YCxCzPlanes& tst, const FeatureFilters& ff,
                       int w, int h, RowPlanes& rows) {
  const float oneOver116 = 1.0f / 116.0f, sixteenOver116 = 16.0f / 116.0f;
  forRows(h, [&](int y) {
    std::vector<float> lum(static_cast<size_t>(w));
    std::vector<float> padded(static_cast<size_t>(w) + 2 * ff.radius);
    const size_t o = static_cast<size_t>(y) * w;
    const Plane* lumPlanes[2] = {&ref.y, &tst.y};
    for (int i = 0; i < 2; ++i) {
      for (int x = 0; x < w; ++x) lum[x] = (*lumPlanes[i])[o + x] * oneOver116 + sixteenOver116;
      padRow(lum.data(), w, ff.radius, padded.data());
      convolveRow(padded.data(), ff.dg, w, rows[4 * i + 0].data() + o);
      convolveRow(padded.data(), ff.ddg, w, rows[4 * i + 1].data() + o);
      convolveRow(padded.data(), ff.g, w, rows[4 * i + 2].data() + o);
    }
  });
}

// Stage 3b + 4: along columns, edge and point strengths, feature difference, final error per
// pixel into result.errorMap and its mean into result.mean.
void featureErrors(const RowPlanes& rows, const FeatureFilters& ff, const Plane& colorDiff, int w,
                   int h, FlipResult& result) {
  const size_t n = static_cast<size_t>(w) * static_cast<size_t>(h);
  result.errorMap.resize(n);
  std::vector<double> rowSums(static_cast<size_t>(h));
  const float invSqrt2 = 1.0f / std::sqrt(2.0f);
  forRows(h, [&](int y) {
    std::vector<float> acc(static_cast<size_t>(w) * 8);
    for (int i = 0; i < 2; ++i) {
      float* b = acc.data() + static_cast<size_t>(4 * i) * w;
      convolveColumn(rows[4 * i + 0], ff.g, w, h, y, b);            // dx
      convolveColumn(rows[4 * i + 1], ff.g, w, h, y, b + w);        // ddx
      convolveColumn(rows[4 * i + 2], ff.dg, w, h, y, b + 2 * w);   // dy
      convolveColumn(rows[4 * i + 2], ff.ddg, w, h, y, b + 3 * w);  // ddy
    }
    const float* a = acc.data();
    const float* t = acc.data() + 4 * static_cast<size_t>(w);
    double sum = 0.0;
    for (int x = 0; x < w; ++x) {
      const float edgeRef = std::sqrt(a[x] * a[x] + a[2 * w + x] * a[2 * w + x]);
      const float edgeTest = std::sqrt(t[x] * t[x] + t[2 * w + x] * t[2 * w + x]);
      const float pointRef = std::sqrt(a[w + x] * a[w + x] + a[3 * w + x] * a[3 * w + x]);
      const float pointTest = std::sqrt(t[w + x] * t[w + x] + t[3 * w + x] * t[3 * w + x]);
      const float edgeDiff = std::fabs(edgeRef - edgeTest);
      const float pointDiff = std::fabs(pointRef - pointTest);
      const float featureDiff = std::pow(invSqrt2 * std::max(edgeDiff, pointDiff), kQf);
      const size_t i = static_cast<size_t>(y) * w + x;
      const float e = std::pow(colorDiff[i], 1.0f - featureDiff);
      result.errorMap[i] = e;
      sum += e;
    }
    rowSums[static_cast<size_t>(y)] = sum;
  });
  double total = 0.0;
  for (double s : rowSums) total += s;
  result.mean = total / static_cast<double>(n);
}

}  // namespace

Result<void> checkFlipPixelsPerDegree(double pixelsPerDegree, Spelling spelling) {
  if (pixelsPerDegree >= kFlipMinPixelsPerDegree && pixelsPerDegree <= kFlipMaxPixelsPerDegree)
    return {};  // false for NaN
  char text[160];
  std::snprintf(text, sizeof text,
                " %g: FLIP's pixels per degree must be in [%g, %g] (its filters are 0.27 ppd "
                "pixels wide; the default is %.2f)",
                pixelsPerDegree, kFlipMinPixelsPerDegree, kFlipMaxPixelsPerDegree,
                kFlipDefaultPixelsPerDegree);
  return makeError(spell(spelling, "--ppd") + text);
}

uint64_t flipWorkingBytes(int width, int height) {
  // per pixel: both images' Y, Cx, Cz planes (6 floats), the eight filtered planes, the colour
  // difference and the error map
  constexpr uint64_t kPerPixel = (6 + 8 + 1 + 1) * sizeof(float);
  return saturatingMul(
      static_cast<uint64_t>(std::max(width, 0)) * static_cast<uint64_t>(std::max(height, 0)),
      kPerPixel);
}

Result<FlipResult> computeFlip(const Image8& reference, const Image8& test,
                               double pixelsPerDegree) {
  MFR_TRY(checkFlipInputs(reference, test, pixelsPerDegree));
  const int w = reference.width, h = reference.height;
  const size_t n = static_cast<size_t>(w) * static_cast<size_t>(h);
  const float ppd = static_cast<float>(pixelsPerDegree);

  std::array<float, 256> decode;
  for (int c = 0; c < 256; ++c) decode[c] = srgbToLinear(static_cast<float>(c) / 255.0f);

  // Stage 1: both images to YCxCz.
  const YCxCzPlanes ref = toYCxCz(reference, decode);
  const YCxCzPlanes tst = toYCxCz(test, decode);

  const SpatialFilters sf = makeSpatialFilters(ppd);
  RowPlanes rows;
  for (Plane& p : rows) p.resize(n);
  spatialFilterRows(ref, tst, sf, w, h, rows);
  const Plane colorDiff = colorDifference(rows, sf, w, h);

  const FeatureFilters ff = makeFeatureFilters(ppd);
  featureFilterRows(ref, tst, ff, w, h, rows);

  FlipResult result;
  result.width = w;
  result.height = h;
  featureErrors(rows, ff, colorDiff, w, h, result);
  return result;
}

Image8 flipErrorImage(const FlipResult& result) {
  return magmaImage(result.errorMap, result.width, result.height, 1.0f);
}

double flipPercentile(const FlipResult& result, double fraction) {
  if (result.errorMap.empty()) return 0.0;
  std::vector<float> sorted = result.errorMap;
  const double f = std::clamp(std::isfinite(fraction) ? fraction : 0.0, 0.0, 1.0);
  const size_t rank = static_cast<size_t>(std::ceil(f * static_cast<double>(sorted.size())));
  const size_t index = rank == 0 ? 0 : rank - 1;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(index),
                   sorted.end());
  return sorted[index];
}

}  // namespace mfr
