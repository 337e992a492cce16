// SPDX-License-Identifier: GPL-2.0-or-later
// The reader against what LinuxCNC 2.9's halcmd did with the same lines (run in halrun):
// where comments start, how continuations join, that quotes stay, which lines it rejects.
#include "linuxcnc/hal_file.hpp"

#include <gtest/gtest.h>

using namespace i20::linuxcnc;

namespace {

std::vector<std::string> words(const Statement& s) {
  std::vector<std::string> out{s.command};
  out.insert(out.end(), s.args.begin(), s.args.end());
  return out;
}

std::string syntax_error(const std::string& text) {
  try {
    read_hal(text, "t.hal");
  } catch (const HalSyntaxError& e) {
    return e.what();
  }
  return "accepted";
}

}  // namespace

TEST(HalFile, ReadsCommandsWithTheirFirstLine) {
  const auto s =
      read_hal("# header\n\nloadrt bldc cfg=qh,a\nsetp bldc.0.rev 1\naddf bldc.0 servo-thread\n", "x.hal");
  ASSERT_EQ(s.size(), 3u);
  EXPECT_EQ(words(s[0]), (std::vector<std::string>{"loadrt", "bldc", "cfg=qh,a"}));
  EXPECT_EQ(s[0].at.text(), "x.hal:3");
  EXPECT_EQ(s[2].at.line, 5);
}

TEST(HalFile, HashStartsACommentAnywhereOutsideQuotes) {
  // halcmd 2.9: `setp and2.0.in0#x 1` is "setp requires 2 arguments, 1 given".
  EXPECT_NE(syntax_error("setp a.b#x 1\n").find("t.hal:1: setp needs 2 words, 1 word given"),
            std::string::npos);
  const auto s = read_hal("setp bldc.0.pattern 17 # 17 or 44\nloadrt x config=\"a # b\"\n", "t.hal");
  EXPECT_EQ(words(s[0]), (std::vector<std::string>{"setp", "bldc.0.pattern", "17"}));
  EXPECT_EQ(s[1].args.at(1), "config=\"a # b\"");
}

TEST(HalFile, BackslashAtTheVeryEndJoinsLinesWithNothingBetween) {
  const auto s = read_hal("setp and2.0.in\\\n0 1\nnet a \\\n  p.out \\\n  q.in\nsetp x.y 1\n", "t.hal");
  ASSERT_EQ(s.size(), 3u);
  EXPECT_EQ(words(s[0]), (std::vector<std::string>{"setp", "and2.0.in0", "1"}));
  EXPECT_EQ(words(s[1]), (std::vector<std::string>{"net", "a", "p.out", "q.in"}));
  EXPECT_EQ(s[1].at.line, 3);  // where the statement starts
  EXPECT_EQ(s[2].at.line, 6);
  // A backslash followed by a space does not continue: halcmd reads "1" as a command.
  EXPECT_NE(syntax_error("setp a.b \\ \n1\n").find("t.hal:2: unknown command '1'"), std::string::npos);
}

TEST(HalFile, AContinuedCommentSwallowsTheNextLine) {
  // halcmd joins first and strips comments after: the second net never happens.
  const auto s = read_hal("net s3 a.in0 # x \\\nnet s4 a.in1\n", "t.hal");
  ASSERT_EQ(s.size(), 1u);
  EXPECT_EQ(words(s[0]), (std::vector<std::string>{"net", "s3", "a.in0"}));
}

TEST(HalFile, QuotesStayInTheWordAsHalcmdKeepsThem) {
  const auto s = read_hal("setp a.b \"1\"\nnet 'sig a' x.y\n", "t.hal");
  EXPECT_EQ(s[0].args[1], "\"1\"");
  EXPECT_EQ(s[1].args[0], "'sig a'");
  EXPECT_EQ(unquoted("config=\"num_encoders=1 x\""), "config=num_encoders=1 x");
}

TEST(HalFile, ArrowsAreDecorationAndEqualsIsSetp) {
  const auto s = read_hal("net a p.out => q.in r.in\nnet b <= p.x\nlinksp sig => q.in\nx.y = 3\n", "t.hal");
  EXPECT_EQ(words(s[0]), (std::vector<std::string>{"net", "a", "p.out", "q.in", "r.in"}));
  EXPECT_EQ(words(s[1]), (std::vector<std::string>{"net", "b", "p.x"}));
  EXPECT_EQ(words(s[2]), (std::vector<std::string>{"linksp", "sig", "q.in"}));
  EXPECT_EQ(words(s[3]), (std::vector<std::string>{"setp", "x.y", "3"}));
}

TEST(HalFile, RejectsWhatHalcmdRejects) {
  EXPECT_EQ(syntax_error("setp a.b \"1 # x\n"), "t.hal:1: unterminated quoted string");
  EXPECT_EQ(syntax_error("\nfoo bar\n"), "t.hal:2: unknown command 'foo'");
  EXPECT_EQ(syntax_error("setp a.b 1 2\n"), "t.hal:1: setp takes at most 2 words, 3 words given");
  EXPECT_EQ(syntax_error("net x\n"), "t.hal:1: net needs a signal name and at least one pin, 1 word given");
  EXPECT_EQ(syntax_error("loadrt\n"), "t.hal:1: loadrt needs 1 word, 0 words given");
  EXPECT_EQ(syntax_error("addf bldc.0\n"), "t.hal:1: addf needs 2 words, 1 word given");
}

TEST(HalFile, DosLineEndingsReadLikeUnix) {
  const auto s = read_hal("setp a.b 1\r\nsetp c.d \\\r\n2\r\n", "t.hal");
  ASSERT_EQ(s.size(), 2u);
  EXPECT_EQ(words(s[1]), (std::vector<std::string>{"setp", "c.d", "2"}));
}
