// The dense-layer kernel for AVX2 + FMA (8 floats per vector); built with -mavx2 -mfma for this
// file only (CMakeLists.txt) and called only when activeIsa() says the CPU has them.
#include <immintrin.h>

#include <cstddef>

#include "learn/mlp_kernels.hpp"

namespace mfr::learn::detail {
namespace {

struct Vec {
  using Type = __m256;
  static constexpr int kNeurons = 6;  // register block: kNeurons x 2 accumulators
  static constexpr int kWidth = 8;
  static Type set1(float v) { return _mm256_set1_ps(v); }
  static Type load(const float* p) { return _mm256_loadu_ps(p); }
  static void store(float* p, Type v) { _mm256_storeu_ps(p, v); }
  static Type fma(Type a, Type b, Type c) { return _mm256_fmadd_ps(a, b, c); }
  // max(0, v) returns its second operand when either is NaN: NaN stays NaN
  static Type relu(Type v) { return _mm256_max_ps(_mm256_setzero_ps(), v); }
};

#include "learn/dense_layer.inc"

}  // namespace

DenseLayerKernel denseLayerAvx2() {
  return &denseLayer;
}

}  // namespace mfr::learn::detail
