// Which instruction set the CPU engine's hot loops run on.
//
// The binary is built for baseline x86-64; the kernels that pay for wider vectors live in their own
// functions compiled for AVX2 (+FMA) or AVX-512 and are chosen once at run time from what the CPU
// reports. `MFR_ISA=scalar|avx2|avx512` forces a path (never one the CPU lacks: asking for more
// than it has falls back to the best it has), so the tests can run the scalar path on any machine.
#pragma once

#include <string_view>

namespace mfr {

enum class Isa { Scalar, Avx2, Avx512 };

/// "scalar", "avx2", "avx512": the name the stats record as "isa".
std::string_view isaName(Isa isa);

/// The best path this CPU supports (AVX2 needs AVX2 + FMA; AVX-512 needs F, BW, DQ and VL).
Isa detectedIsa();

/// The path the engine takes: detectedIsa() lowered by MFR_ISA when set (read once per process;
/// an unknown value is ignored with a one-line warning on stderr).
Isa activeIsa();

/// For tests and benchmarks: force the path for the rest of the process (clamped to detectedIsa()).
void setActiveIsa(Isa isa);

}  // namespace mfr
