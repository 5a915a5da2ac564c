// The dense-layer kernel for AVX-512 (16 floats per vector); built with -mavx512f -mfma for this
// file only (CMakeLists.txt) and called only when activeIsa() says the CPU has them.
#include <immintrin.h>

#include <cstddef>

#include "learn/mlp_kernels.hpp"

namespace mfr::learn::detail {
namespace {

struct Vec {
  using Type = __m512;
  static constexpr int kNeurons = 8;  // register block: kNeurons x 2 accumulators
  static constexpr int kWidth = 16;
  static Type set1(float v) { return _mm512_set1_ps(v); }
  static Type load(const float* p) { return _mm512_loadu_ps(p); }
  static void store(float* p, Type v) { _mm512_storeu_ps(p, v); }
  static Type fma(Type a, Type b, Type c) { return _mm512_fmadd_ps(a, b, c); }
  // max(0, v) returns its second operand when either is NaN: NaN stays NaN (the masked form,
  // all lanes, because GCC 12 flags the unmasked one's undefined pass-through operand)
  static Type relu(Type v) {
    const Type zero = _mm512_setzero_ps();
    return _mm512_mask_max_ps(zero, static_cast<__mmask16>(0xffff), zero, v);
  }
};

#include "learn/dense_layer.inc"

}  // namespace

DenseLayerKernel denseLayerAvx512() {
  return &denseLayer;
}

}  // namespace mfr::learn::detail
