// Wide inference kernels of the deep k-buffer's network (DHOIT sec. 3.1.3, Fig. 4): one dense
// layer over a batch of samples, compiled per instruction set in its own translation unit
// (mlp_kernel_avx2.cpp with -mavx2 -mfma, mlp_kernel_avx512.cpp with -mavx512f ...), chosen at
// run time with activeIsa() (core/isa.hpp). The scalar path is Eigen's (mlp.cpp).
//
// Layout of a batch (feature-major, samples contiguous, so one vector holds one feature of 8 or
// 16 samples):
//
//   in / out:  [ feature 0: s0 s1 ... s(stride-1) ][ feature 1: ... ] ...   floats
//   stride  :  the batch size rounded up to kBatchAlign; padded samples hold any finite value and
//              their results are ignored
//
// Every sample's sum runs in the same order whatever its position in the batch and whatever the
// batch size (bias first, then inputs 0, 1, ... with one fused multiply-add each), so a pixel's
// result never depends on its tile, the batch or the thread count.
#pragma once

#include <cstddef>

namespace mfr::learn::detail {

/// Batch strides are multiples of this (two AVX-512 vectors).
inline constexpr int kBatchAlign = 32;

/// out[o][j] = act(b[o] + sum_i w(o, i) in[i][j]) for j < stride; `w` column-major (rows x cols,
/// Eigen's layout: w(o, i) = w[i * rows + o]); act = max(0, .) when `relu`, else identity. A NaN
/// sum stays NaN through the ReLU (as in Eigen's path).
using DenseLayerKernel = void (*)(const float* w, const float* b, int rows, int cols,
                                  const float* in, float* out, int stride, bool relu);

DenseLayerKernel denseLayerAvx2();
DenseLayerKernel denseLayerAvx512();

}  // namespace mfr::learn::detail
