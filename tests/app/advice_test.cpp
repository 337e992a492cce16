// SPDX-License-Identifier: GPL-2.0-or-later
// lib/ says what happened and marks what overrides it (i20::Advice); each program names the
// option for it, and only an option it has: a program without --force never suggests it.
#include <gtest/gtest.h>

#include <CLI/CLI.hpp>

#include "errors.hpp"
#include "options.hpp"

using namespace i20;

namespace {

// Restores "no overrides" after each test: the setting is the process's.
class AppAdvice : public ::testing::Test {
 protected:
  void TearDown() override { app::set_overrides({}); }
};

}  // namespace

TEST_F(AppAdvice, AProgramNamesTheOptionsItHas) {
  CLI::App wpd;
  bool force = false, unverified = false;
  app::GlobalOptions options;
  wpd.add_flag("--force", force);
  wpd.add_flag("--allow-unverified", unverified);
  app::add_target_options(wpd, options);
  app::set_overrides(app::overrides_of(wpd));
  EXPECT_EQ(app::advice_text(i20::Advice::Force), "; pass --force to override");
  EXPECT_EQ(app::advice_text(i20::Advice::AllowUnverified), "; pass --allow-unverified if you know better");
  EXPECT_EQ(app::advice_text(i20::Advice::RunningHost), " (--take-over)");
  EXPECT_EQ(app::advice_text(i20::Advice::None), "");
  EXPECT_EQ(app::with_advice("refused", i20::Advice::Force), "refused; pass --force to override");
}

TEST_F(AppAdvice, AProgramWithoutTheOptionSuggestsNothing) {
  CLI::App rpd;  // rpd: --allow-unverified and the target options, no --force
  bool unverified = false;
  app::GlobalOptions options;
  rpd.add_flag("--allow-unverified", unverified);
  app::add_target_options(rpd, options);
  app::set_overrides(app::overrides_of(rpd));
  EXPECT_EQ(app::advice_text(i20::Advice::Force), "");
  EXPECT_EQ(app::with_advice("refused", i20::Advice::Force), "refused");
  EXPECT_NE(app::advice_text(i20::Advice::AllowUnverified), "");
  // Nothing set at all (a program that never said what it has): nothing named.
  app::set_overrides({});
  EXPECT_EQ(app::advice_text(i20::Advice::AllowUnverified), "");
  EXPECT_EQ(app::advice_text(i20::Advice::RunningHost), "");
}

TEST_F(AppAdvice, AnUmbrellaNamesTheOptionsOfTheCommandGiven) {
  CLI::App i20;
  app::GlobalOptions options;
  app::add_target_options(i20, options);  // global: every command has --take-over
  bool force = false, unverified = false;
  auto* set = i20.add_subcommand("set");
  set->add_flag("--force", force);
  set->add_flag("--allow-unverified", unverified);
  auto* faults = i20.add_subcommand("faults");
  auto* clear = faults->add_subcommand("clear");
  clear->add_flag("--allow-unverified", unverified);

  i20.parse(std::vector<std::string>{"clear", "faults"});  // CLI11 takes them last to first
  auto o = app::overrides_of_parsed(i20);
  EXPECT_TRUE(o.take_over);
  EXPECT_TRUE(o.allow_unverified);
  EXPECT_FALSE(o.force) << "`faults clear` has no --force";

  i20.clear();
  i20.parse(std::vector<std::string>{"set"});
  o = app::overrides_of_parsed(i20);
  EXPECT_TRUE(o.force);
  EXPECT_TRUE(o.allow_unverified);
  EXPECT_TRUE(o.take_over);
}
