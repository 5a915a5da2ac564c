// Variable k-buffer (/work/shared/papers/variable-k-buffer-importance-maps.md sec. 3.1): the total
// importance I_tot = sum of I(p), for P(p) = I(p) / I_tot. One invocation adds the pixels in order
// in double, as mfr::allocate does on the host, so that I_tot and hence every k(p) are bit for bit
// the CPU engine's (a parallel reduction would round differently). O(pixels) serial work: a few ms
// for a megapixel on llvmpipe.
layout(local_size_x = 1) in;

layout(std430, binding = kBindImportance) readonly buffer Importance {
  float importance[];  // kImportanceWords per pixel, I(p) first
};
layout(std430, binding = kBindImportanceTotal) writeonly buffer Total {
  double total;
};
uniform uint uPixels;

void main() {
  precise double sum = 0.0lf;
  for (uint p = 0u; p < uPixels; ++p) sum += double(importance[p * kImportanceWords]);
  total = sum;
}
