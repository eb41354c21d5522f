#include "camproj/terminal_text.h"

#include <gtest/gtest.h>

namespace camproj {
namespace {

TEST(TerminalTextTest, ControlsAreEscapedAndTheRestKept) {
  EXPECT_EQ(TerminalSafe("\x1b[31mred\x1b[0m"), "\\x1b[31mred\\x1b[0m");
  EXPECT_EQ(TerminalSafe(std::string("a\0b\x7f", 4)), "a\\x00b\\x7f");
  EXPECT_EQ(TerminalSafe("line 1\n\tline 2\r"), "line 1\n\tline 2\\x0d");
  // U+009B (CSI) in UTF-8 is C2 9B; other UTF-8 (e, with an acute accent: C3 A9) stays.
  EXPECT_EQ(TerminalSafe("\xc2\x9b" "2J caf\xc3\xa9"), "\\u009b2J caf\xc3\xa9");
  EXPECT_EQ(TerminalSafe("\xc2"), "\xc2");  // a lone lead byte at the end is not a C1 control
}

}  // namespace
}  // namespace camproj
