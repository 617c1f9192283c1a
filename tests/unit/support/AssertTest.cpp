// QDOT_ASSERT / QDOT_UNREACHABLE: a broken invariant stops qdot and says where and why.
#include <gtest/gtest.h>

#include "support/Assert.h"

namespace qdot::test {
namespace {

int checkedHalf(int n) {
  QDOT_ASSERT(n % 2 == 0, "only even numbers are halved");
  return n / 2;
}

TEST(AssertDeathTest, UnreachableNamesTheFileTheLineAndTheReason) {
  EXPECT_DEATH(QDOT_UNREACHABLE("every kind is handled above"),
               "AssertTest.cpp:[0-9]+: qdot internal error: every kind is handled above \\(unreachable\\)");
}

TEST(AssertDeathTest, AssertionHoldsOrStopsInDebugAndFuzzBuilds) {
  EXPECT_EQ(checkedHalf(4), 2);
#if !defined(NDEBUG) || defined(QDOT_FUZZ)
  EXPECT_DEATH(checkedHalf(3), "qdot internal error: only even numbers are halved \\(n % 2 == 0\\)");
#else
  EXPECT_EQ(checkedHalf(3), 1);  // Release: the check costs nothing and is not made
#endif
}

}  // namespace
}  // namespace qdot::test
