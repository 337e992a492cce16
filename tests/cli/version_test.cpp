// SPDX-License-Identifier: GPL-2.0-or-later
// Every program says which version it is, the CMake project's (`project(i20tools VERSION ...)`),
// as help2man and bug reports expect: "PROGRAM VERSION" on one line, exit 0, even where a
// subcommand or positional argument is otherwise required.
#include <gtest/gtest.h>

#include "harness.hpp"

using namespace i20::test;

TEST(Version, EveryProgramPrintsTheProjectVersion) {
  for (const std::string program : {"i20", "wpd", "rpd", "i20sim"}) {
    const auto r = run(program, {"--version"});
    EXPECT_EQ(r.exit_code, 0) << program << ": " << r.err;
    EXPECT_EQ(r.out, program + " " + I20_TEST_VERSION + "\n") << program;
  }
}
