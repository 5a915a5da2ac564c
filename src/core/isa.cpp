#include "mfr/core/isa.hpp"

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace mfr {

std::string_view isaName(Isa isa) {
  switch (isa) {
    case Isa::Avx512:
      return "avx512";
    case Isa::Avx2:
      return "avx2";
    case Isa::Scalar:
      break;
  }
  return "scalar";
}

Isa detectedIsa() {
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
  __builtin_cpu_init();
  const bool avx2 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  const bool avx512 = avx2 && __builtin_cpu_supports("avx512f") &&
                      __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512dq") &&
                      __builtin_cpu_supports("avx512vl");
  return avx512 ? Isa::Avx512 : avx2 ? Isa::Avx2 : Isa::Scalar;
#else
  return Isa::Scalar;
#endif
}

namespace {

Isa clampToCpu(Isa wanted) {
  const Isa best = detectedIsa();
  return static_cast<int>(wanted) < static_cast<int>(best) ? wanted : best;
}

Isa fromEnvironment() {
  const Isa best = detectedIsa();
  const char* env = std::getenv("MFR_ISA");
  if (env == nullptr || *env == '\0') return best;
  const std::string value = env;
  for (Isa isa : {Isa::Scalar, Isa::Avx2, Isa::Avx512})
    if (value == isaName(isa)) return clampToCpu(isa);
  std::fprintf(stderr, "mfr: ignoring MFR_ISA=%s (expected scalar, avx2 or avx512)\n", env);
  return best;
}

std::atomic<int>& activeSlot() {
  static std::atomic<int> slot{static_cast<int>(fromEnvironment())};
  return slot;
}

}  // namespace

Isa activeIsa() {
  return static_cast<Isa>(activeSlot().load(std::memory_order_relaxed));
}

void setActiveIsa(Isa isa) {
  activeSlot().store(static_cast<int>(clampToCpu(isa)), std::memory_order_relaxed);
}

}  // namespace mfr
