// The run-time instruction-set choice: forcing a path never exceeds what the CPU has, and the names
// are the ones the stats record.
#include <gtest/gtest.h>

#include "mfr/core/isa.hpp"

namespace mfr {
namespace {

TEST(Isa, NamesAreTheStatsValues) {
  EXPECT_EQ(isaName(Isa::Scalar), "scalar");
  EXPECT_EQ(isaName(Isa::Avx2), "avx2");
  EXPECT_EQ(isaName(Isa::Avx512), "avx512");
}

TEST(Isa, ForcingClampsToTheCpuAndRestores) {
  const Isa before = activeIsa();
  setActiveIsa(Isa::Scalar);
  EXPECT_EQ(activeIsa(), Isa::Scalar);
  setActiveIsa(Isa::Avx512);  // more than some CPUs have: lowered to the best it supports
  EXPECT_EQ(activeIsa(), detectedIsa());
  setActiveIsa(before);
  EXPECT_EQ(activeIsa(), before);
}

}  // namespace
}  // namespace mfr
