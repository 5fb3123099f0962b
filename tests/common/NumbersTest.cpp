#include <gtest/gtest.h>

#include "urbanslam/common/Numbers.h"

using namespace urbanslam::common;

TEST(Numbers, DecimalNumbersParse) {
  EXPECT_EQ(parseDecimal("-12"), -12.0);
  EXPECT_EQ(parseDecimal("3.5"), 3.5);
  EXPECT_EQ(parseDecimal(".5"), 0.5);
  EXPECT_EQ(parseDecimal("5."), 5.0);
  EXPECT_EQ(parseDecimal("+2.5E+04"), 25000.0);
  EXPECT_EQ(parseDecimal("1.13487e+09"), 1.13487e9);
  EXPECT_EQ(parseDecimal("1e-400"), 0.0);  // underflow is harmless
  EXPECT_EQ(parseWholeNumber("180"), 180);
  EXPECT_EQ(parseWholeNumber("-7"), -7);
}

// strtod takes all of these; in a log each is corruption.
TEST(Numbers, HexInfinityNanAndJunkAreRejected) {
  for (const char* bad : {"0x7fffffff", "0X1p3", "inf", "-inf", "infinity", "nan", "NAN(1)", "1e400", "-1e309", "",    "+",  "-",
                          ".",          "e5",    "1e",  "1e+",  "1.2.3",    " 1",  "1 ",     "1,5",   "++1",    "+-1", "1f", "١"})
    EXPECT_FALSE(parseDecimal(bad).has_value()) << bad;
  for (const char* bad : {"0x10", "1.0", "1e3", "", "-", "99999999999999999999", " 3", "3 "})
    EXPECT_FALSE(parseWholeNumber(bad).has_value()) << bad;
}
