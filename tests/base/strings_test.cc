#include "OpenABLE/base/strings.h"

#include <gtest/gtest.h>

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

}  // namespace
}  // namespace openable
