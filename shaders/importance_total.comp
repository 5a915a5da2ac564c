// Variable k-buffer (/work/shared/papers/variable-k-buffer-importance-maps.md sec. 3.1): the total
// importance I_tot = sum of I(p), for P(p) = I(p) / I_tot. One invocation adds the pixels in order
// in double, as mfr::allocate does on the host, so that I_tot and hence every k(p) are bit for bit
// the CPU engine's (a parallel reduction would round differently). O(pixels) serial work, split
// into dispatches of kTotalChunk pixels [uFirst, uEnd) that carry the running sum in `total`:
// llvmpipe ends a shader's loops after 65535 iterations in all (gallivm's loop limiter).
layout(local_size_x = 1) in;

layout(std430, binding = kBindImportance) readonly buffer Importance {
  float importance[];  // kImportanceWords per pixel, I(p) first
};
layout(std430, binding = kBindImportanceTotal) buffer Total {
  double total;
};
uniform uint uFirst;
uniform uint uEnd;

void main() {
  precise double sum = uFirst == 0u ? 0.0lf : total;
  for (uint p = uFirst; p < uEnd; ++p) sum += double(importance[p * kImportanceWords]);
  total = sum;
}
