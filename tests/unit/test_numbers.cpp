// Unit tests of the number parsing and printing every style shares (src-liggghts-eepa/common/numbers.h).
#include <gtest/gtest.h>

#include <climits>
#include <cmath>
#include <string>

#include "numbers.h"

namespace {

TEST(ParseReal, WholeFiniteTokensOnly)
{
  double v = -1;
  EXPECT_TRUE(tsg::parse_real("1e-3", v));
  EXPECT_DOUBLE_EQ(v, 1e-3);
  EXPECT_TRUE(tsg::parse_real("-2.5", v));
  EXPECT_DOUBLE_EQ(v, -2.5);
  for (const char *bad : {"", "5cm", "1.2.3", "nan", "inf", "-inf", "1e999", "1e-400", "x", "-", " "})
    EXPECT_FALSE(tsg::parse_real(bad, v)) << bad;
  EXPECT_FALSE(tsg::parse_real(nullptr, v));
}

TEST(ScanReal, WholeTokensWhateverTheirValue)
{
  // the keywords that tell "not a number" from "outside the allowed range" (fix check/contact)
  double v = 0;
  EXPECT_TRUE(tsg::scan_real("nan", v));
  EXPECT_TRUE(std::isnan(v));
  EXPECT_TRUE(tsg::scan_real("1e999", v));
  EXPECT_TRUE(std::isinf(v));
  EXPECT_TRUE(tsg::scan_real("1e-400", v));
  EXPECT_EQ(v, 0.0);
  for (const char *bad : {"", "0.5x", "1.2.3", "-", " "}) EXPECT_FALSE(tsg::scan_real(bad, v)) << bad;
}

TEST(ParseInteger, WholeTokensInTheRange)
{
  long n = 0;
  EXPECT_TRUE(tsg::parse_integer("42", 1, 100, n));
  EXPECT_EQ(n, 42);
  EXPECT_TRUE(tsg::parse_integer("-7", LONG_MIN, LONG_MAX, n));
  EXPECT_EQ(n, -7);
  for (const char *bad : {"", "0", "101", "4.2", "1e2", "12a", "99999999999999999999999"})
    EXPECT_FALSE(tsg::parse_integer(bad, 1, 100, n)) << bad;
}

TEST(Number, EachKindKeepsItsDigits)
{
  const double third = 1.0 / 3.0;
  EXPECT_EQ(tsg::number(third), "0.3333333333");  // record: 10 significant digits
  EXPECT_EQ(tsg::number(third, tsg::NumberKind::record), "0.3333333333");
  EXPECT_EQ(tsg::number(third, tsg::NumberKind::setup), "0.333333");
  EXPECT_EQ(tsg::number(third, tsg::NumberKind::guard), "0.3333");
  EXPECT_EQ(tsg::number(0.25), "0.25");  // no trailing zeros
  EXPECT_EQ(tsg::number(1e-12, tsg::NumberKind::guard), "1e-12");
  EXPECT_EQ(tsg::number(1234567.0, tsg::NumberKind::guard), "1.235e+06");
}

TEST(Number, ParameterKindAsWritten)
{
  using tsg::NumberKind;
  EXPECT_EQ(tsg::number(0.5, NumberKind::parameter), "0.5");
  EXPECT_EQ(tsg::number(-0.001, NumberKind::parameter), "-0.001");
  EXPECT_EQ(tsg::number(-1e-4, NumberKind::parameter), "-1e-4");
  EXPECT_EQ(tsg::number(-1e-9, NumberKind::parameter), "-1e-9");
  EXPECT_EQ(tsg::number(2.5e-9, NumberKind::parameter), "2.5e-9");
  EXPECT_EQ(tsg::number(-3.5e5, NumberKind::parameter), "-350000");
  EXPECT_EQ(tsg::number(0.0, NumberKind::parameter), "0");
  EXPECT_EQ(tsg::number(std::nan(""), NumberKind::parameter), "nan");
  EXPECT_EQ(tsg::number(-HUGE_VAL, NumberKind::parameter), "-inf");
}

}  // namespace
