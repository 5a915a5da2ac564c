// MFR_CHECK_EQ and its kin: a failing check prints both expressions and both values, then aborts.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>

#include "mfr/core/result.hpp"

namespace mfr {
namespace {

TEST(CheckMacros, PassingChecksDoNothing) {
  const int three = 3, five = 5;
  MFR_CHECK_EQ(three, 3);
  MFR_CHECK_NE(three, five);
  MFR_CHECK_LT(three, five);
  MFR_CHECK_LE(three, three);
  MFR_CHECK_GT(five, three);
  MFR_CHECK_GE(five, five);
}

TEST(CheckMacros, OperandsEvaluatedOnce) {
  int calls = 0;
  auto next = [&] { return ++calls; };
  MFR_CHECK_EQ(next(), 1);
  EXPECT_EQ(calls, 1);
}

TEST(CheckMacrosDeathTest, FailingLePrintsBothValues) {
  const uint64_t used = 5, budget = 3;
  EXPECT_DEATH(MFR_CHECK_LE(used, budget), "internal check failed: used <= budget \\(5 vs\\. 3\\)");
}

TEST(CheckMacrosDeathTest, FailingEqPrintsFloatsAndStrings) {
  const double x = 0.5;
  EXPECT_DEATH(MFR_CHECK_EQ(x, 0.25), "x == 0\\.25 \\(0\\.5 vs\\. 0\\.25\\)");
  const std::string name = "abuffer";
  EXPECT_DEATH(MFR_CHECK_EQ(name, std::string("kbuffer")), "\\(abuffer vs\\. kbuffer\\)");
}

}  // namespace
}  // namespace mfr
