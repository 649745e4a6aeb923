#include "OpenABLE/base/strings.h"

#include <gtest/gtest.h>

#include <limits>

namespace openable {
namespace {

TEST(Strings, SplitTrimmedKeepsEmptyPieces) {
  EXPECT_EQ(SplitTrimmed(" a , b,c ", ','), (std::vector<std::string>{"a", "b", "c"}));
  EXPECT_EQ(SplitTrimmed("a,,b", ','), (std::vector<std::string>{"a", "", "b"}));
  EXPECT_EQ(SplitTrimmed("", ','), (std::vector<std::string>{""}));
  EXPECT_EQ(SplitTrimmed("x | y |", '|'), (std::vector<std::string>{"x", "y", ""}));
  EXPECT_EQ(SplitTrimmed("1,1;2,1", ';'), (std::vector<std::string>{"1,1", "2,1"}));
}

TEST(Strings, TrimAndFormat) {
  EXPECT_EQ(Trim(" \tx y\r\n"), "x y");
  EXPECT_EQ(FormatFixed(0.12345, 3), "0.123");
  EXPECT_EQ(FormatNumber(2500), "2500");
}

// The texts printf's %g writes, as the reports and files have always held them.
TEST(Strings, FormatNumberWritesPrintfG) {
  EXPECT_EQ(FormatNumber(0.47), "0.47");
  EXPECT_EQ(FormatNumber(1e6), "1e+06");
  EXPECT_EQ(FormatNumber(1234567.0), "1.23457e+06");
  EXPECT_EQ(FormatNumber(1.0 / 3.0, 9), "0.333333333");
  EXPECT_EQ(FormatNumber(0.1 + 0.2, 9), "0.3");
  EXPECT_EQ(FormatNumber(0.1 + 0.2, 17), "0.30000000000000004");
  EXPECT_EQ(FormatNumber(1e-5, 9), "1e-05");
  EXPECT_EQ(FormatNumber(-2.5, 9), "-2.5");
  EXPECT_EQ(FormatNumber(std::numeric_limits<double>::infinity()), "inf");
  EXPECT_EQ(FormatNumber(-std::numeric_limits<double>::infinity(), 9), "-inf");
  EXPECT_EQ(FormatNumber(std::numeric_limits<double>::quiet_NaN()), "nan");
  EXPECT_EQ(FormatFixed(2.0 / 3.0, 9), "0.666666667");
  EXPECT_EQ(FormatFixed(-0.04, 1), "-0.0");
}

}  // namespace
}  // namespace openable
