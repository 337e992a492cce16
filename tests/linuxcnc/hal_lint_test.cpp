// SPDX-License-Identifier: GPL-2.0-or-later
// Each lint rule on a small HAL snippet: it fires on the mistake, on the right line, and is
// quiet on the corrected line.
#include "linuxcnc/hal_lint.hpp"

#include <gtest/gtest.h>

using namespace i20::linuxcnc;

namespace {

constexpr const char* kDev = "hm2_7i96s.0.8i20.0.0";

std::vector<LintFinding> lint_text(const std::string& text, LintOptions options = {}) {
  return lint(read_hal(text, "t.hal"), options);
}

std::vector<LintFinding> of_rule(const std::vector<LintFinding>& all, const std::string& rule) {
  std::vector<LintFinding> out;
  for (const auto& f : all)
    if (f.rule == rule) out.push_back(f);
  return out;
}

std::vector<int> lines(const std::vector<LintFinding>& findings) {
  std::vector<int> out;
  for (const auto& f : findings) out.push_back(f.at.line);
  return out;
}

std::string dev(const std::string& rest) {
  return std::string(kDev) + "." + rest;
}

// A correct axis: rotor-angle to angle, faults into a gate, pid driven, inputs connected.
std::string good_axis() {
  return "loadrt pid num_chan=1\n"
         "loadrt bldc cfg=qh\n"
         "net pos-cmd joint.0.motor-pos-cmd pid.0.command\n"
         "net pos-fb hm2_7i96s.0.encoder.00.position pid.0.feedback\n"
         "net enable joint.0.amp-enable-out pid.0.enable\n"
         "net torque pid.0.output bldc.0.value\n"
         "net raw hm2_7i96s.0.encoder.00.rawcounts bldc.0.rawcounts\n"
         "net h1 hm2_7i96s.0.inm.00.input-00 bldc.0.hall1\n"
         "net h2 hm2_7i96s.0.inm.00.input-01 bldc.0.hall2\n"
         "net h3 hm2_7i96s.0.inm.00.input-02 bldc.0.hall3\n"
         "net rotor bldc.0.rotor-angle " +
         dev("angle") + "\nnet cur bldc.0.out " + dev("current") + "\nnet flt " + dev("fault.watchdog") +
         " logic.0.in-00\nsetp pid.0.maxoutput 10\n";
}

}  // namespace

TEST(HalLint, ACorrectAxisHasNoFindings) {
  const auto findings = lint_text(good_axis(), {10.0, std::nullopt});
  for (const auto& f : findings) ADD_FAILURE() << to_string(f);
}

TEST(HalLint, ObsoleteEightI20NamesWithTheirReplacement) {
  const auto f =
      of_rule(lint_text("setp " + dev("max_current") + " 30.0\nnet on x.out " + dev("amp_enable") +
                        "\nnet v " + dev("voltage") + " pyvcp.v\nnet t " + dev("temp") + " pyvcp.t\n"),
              "obsolete-8i20-name");
  ASSERT_EQ(lines(f), (std::vector<int>{1, 2, 3, 4}));
  EXPECT_EQ(f[0].severity, LintSeverity::Error);
  EXPECT_NE(f[0].fix.find("MAXCURRENT"), std::string::npos);
  EXPECT_NE(f[1].fix.find("no enable pin"), std::string::npos);
  EXPECT_NE(f[2].fix.find("bus-voltage"), std::string::npos);
  EXPECT_NE(f[3].fix.find("card-temp"), std::string::npos);
  // Today's names of the same things are fine.
  EXPECT_TRUE(
      of_rule(lint_text("net v " + dev("bus-voltage") + " pyvcp.v\nnet t " + dev("card-temp") + " pyvcp.t\n"),
              "obsolete-8i20-name")
          .empty());
}

TEST(HalLint, SerialNumberNamesAreEightI20NamesToo) {
  const auto f = of_rule(lint_text("net on x.out hm2_8i20.1a2b.amp_enable\n"), "obsolete-8i20-name");
  EXPECT_EQ(lines(f), std::vector<int>{1});
}

TEST(HalLint, PhaseAngleIntoTheEightI20IsASecondLead) {
  const std::string base = "loadrt bldc cfg=qh\nnet a bldc.0.phase-angle " + dev("angle") + "\n";
  const auto by_default = of_rule(lint_text(base), "second-lead");
  ASSERT_EQ(lines(by_default), std::vector<int>{2});
  EXPECT_NE(by_default[0].message.find("90 degrees"), std::string::npos);
  EXPECT_NE(by_default[0].fix.find("rotor-angle"), std::string::npos);
  // An explicit lead-angle 90 (PnCconf's %d) is named with its line.
  const auto explicit90 = of_rule(lint_text(base + "setp bldc.0.lead-angle 90\n"), "second-lead");
  ASSERT_EQ(explicit90.size(), 1u);
  EXPECT_NE(explicit90[0].message.find("t.hal:3"), std::string::npos);
  // lead-angle 0 makes phase-angle equal rotor-angle: no second lead.
  EXPECT_TRUE(of_rule(lint_text(base + "setp bldc.0.lead-angle 0\n"), "second-lead").empty());
  // Hall-only mode has no lead-angle to set: its phase-angle always leads a quarter turn.
  const auto hall_only =
      of_rule(lint_text("loadrt bldc cfg=h\nnet a bldc.0.phase-angle " + dev("angle") + "\n"), "second-lead");
  ASSERT_EQ(hall_only.size(), 1u);
  EXPECT_EQ(hall_only[0].fix.find("setp"), std::string::npos);
}

TEST(HalLint, ChangedCurrentScalingAndLimitsAboveMaxcurrent) {
  const std::string text = "setp " + dev("current-scalemax") + " 1.0\nsetp " + dev("current-maxlim") +
                           " 40\nsetp " + dev("current-minlim") + " -5\n";
  const auto scaling = of_rule(lint_text(text), "current-scaling");
  EXPECT_EQ(lines(scaling), std::vector<int>{1});
  EXPECT_EQ(scaling[0].severity, LintSeverity::Warning);
  // Limits are judged only against a known MAXCURRENT.
  EXPECT_TRUE(of_rule(lint_text(text), "current-above-max").empty());
  EXPECT_EQ(lines(of_rule(lint_text(text, {20.0, std::nullopt}), "current-above-max")), std::vector<int>{2});
}

TEST(HalLint, PidOutputThatCanExceedMaxcurrent) {
  const std::string chain =
      "loadrt pid num_chan=1\nloadrt bldc cfg=qh\nnet t pid.0.output bldc.0.value\nnet c bldc.0.out " +
      dev("current") + "\n";
  // maxoutput unset is 0, which pid reads as no limit.
  const auto unset = of_rule(lint_text(chain, {12.0, std::nullopt}), "current-above-max");
  ASSERT_EQ(lines(unset), std::vector<int>{4});
  EXPECT_NE(unset[0].message.find("no limit"), std::string::npos);
  EXPECT_EQ(lines(of_rule(lint_text(chain + "setp pid.0.maxoutput 15\n", {12.0, std::nullopt}),
                          "current-above-max")),
            std::vector<int>{5});
  EXPECT_TRUE(
      of_rule(lint_text(chain + "setp pid.0.maxoutput 12\n", {12.0, std::nullopt}), "current-above-max")
          .empty());
  // An INI value cannot be judged here.
  EXPECT_TRUE(of_rule(lint_text(chain + "setp pid.0.maxoutput [JOINT_0]MAX_OUTPUT\n", {12.0, std::nullopt}),
                      "current-above-max")
                  .empty());
  // A pid named with names= counts too.
  const auto named = of_rule(
      lint_text("loadrt pid names=pid.x\nnet c pid.x.output " + dev("current") + "\n", {5.0, std::nullopt}),
      "current-above-max");
  EXPECT_EQ(named.size(), 1u);
}

TEST(HalLint, BldcPinsTheCfgDoesNotCreate) {
  const auto f = lint_text(
      "loadrt bldc cfg=h\n"
      "net r enc.rawcounts bldc.0.rawcounts\n"
      "net i bldc.0.init\n"
      "setp bldc.0.pattern 17\n"
      "net z bldc.1.value\n"
      "addf bldc.2 servo-thread\n"
      "setp bldc.0.bogus 1\n");
  const auto cfg = of_rule(f, "bldc-cfg");
  ASSERT_EQ(lines(cfg), (std::vector<int>{2, 3}));
  EXPECT_NE(cfg[0].message.find("with a or q"), std::string::npos);
  EXPECT_NE(cfg[1].message.find("with q and none of h"), std::string::npos);
  // A name no cfg creates is no cfg's matter: it does not exist at all.
  const auto unknown = of_rule(f, "unknown-name");
  ASSERT_EQ(lines(unknown), (std::vector<int>{7}));
  EXPECT_NE(unknown[0].message.find("bldc.0 (cfg=h) has no pin, param or function 'bogus'"),
            std::string::npos)
      << unknown[0].message;
  EXPECT_EQ(lines(of_rule(f, "bldc-instance")), (std::vector<int>{5, 6}));
}

TEST(HalLint, AHugeBldcInstanceNumberIsJustANameNotACrash) {
  EXPECT_NO_THROW(lint_text("loadrt bldc cfg=qh\nnet x bldc.99999999999999999999.value\n"));
  EXPECT_EQ(lines(of_rule(lint_text("loadrt bldc cfg=qh\nnet x bldc.999999.value\n"), "bldc-instance")),
            std::vector<int>{2});
}

// A bldc whose out is netted back to its own value (or two bldcs feeding each other) is a
// loop in the file, not in the linter: the 8I20's current is still traced to its pid.
TEST(HalLint, ABldcLoopedOnItselfIsFollowedOnce) {
  const std::string looped = good_axis() + "net loop bldc.0.out bldc.0.value\n";
  std::vector<LintFinding> findings;
  ASSERT_NO_THROW(findings = lint_text(looped, {10.0, std::nullopt}));
  const std::string two =
      "loadrt bldc cfg=qh,qh\nnet a bldc.0.out bldc.1.value\nnet b bldc.1.out bldc.0.value pid.0.output\n"
      "net c bldc.0.out\nsetp pid.0.maxoutput 0\n";
  EXPECT_NO_THROW(lint_text(two, {10.0, std::nullopt}));
}

TEST(HalLint, BldcNamesAreNotJudgedWhenTheCfgComesFromTheIniFile) {
  EXPECT_TRUE(lint_text("loadrt bldc cfg=[BLDC]CFG\nnet i bldc.0.init\nnet r bldc.1.rawcounts\n").empty());
}

TEST(HalLint, BldcNamesAreNotJudgedWithoutItsLoadLine) {
  // A postgui file alone: its bldc was loaded by another file.
  EXPECT_TRUE(lint_text("net p bldc.0.phase-angle pyvcp.p\nnet x bldc.3.init\n").empty());
}

TEST(HalLint, BldcLoadLinesThatMakeNoUsableInstances) {
  EXPECT_EQ(lines(of_rule(lint_text("loadrt bldc cfg=h,h,h,h,h,h,h,h,h\n"), "bldc-instances")),
            std::vector<int>{1});
  // LinuxCNC 2.9: without cfg bldc loads with no instance; names= makes the load fail.
  EXPECT_EQ(lines(of_rule(lint_text("\nloadrt bldc\n"), "bldc-instances")), std::vector<int>{2});
  EXPECT_EQ(lines(of_rule(lint_text("loadrt bldc names=x cfg=qh\n"), "bldc-instances")), std::vector<int>{1});
  EXPECT_TRUE(of_rule(lint_text("loadrt bldc cfg=qh\n"), "bldc-instances").empty());
}

TEST(HalLint, ValuesThatAreClearlyNotMeant) {
  const auto f = lint_text(
      "loadrt bldc cfg=q\n"
      "setp bldc.0.initvalue 0\n"
      "setp bldc.0.drive-offset 400\n"
      "setp bldc.0.lead-angle 0.25\n"
      "setp bldc.0.lead-angle 720\n"
      "setp bldc.0.initvalue 0.2\n"
      "setp bldc.0.drive-offset 90\n");
  EXPECT_EQ(lines(of_rule(f, "initvalue-zero")), std::vector<int>{2});
  EXPECT_EQ(lines(of_rule(f, "angle-range")), (std::vector<int>{3, 4, 5}));
}

TEST(HalLint, FaultPinsThatReachNothing) {
  const std::string axis = "net a bldc.0.rotor-angle " + dev("angle") + "\n";
  const auto none = of_rule(lint_text(axis), "faults-unconnected");
  ASSERT_EQ(lines(none), std::vector<int>{1});
  EXPECT_EQ(none[0].severity, LintSeverity::Warning);
  EXPECT_NE(none[0].message.find(kDev), std::string::npos);
  // A fault pin alone on its signal still reaches nothing.
  EXPECT_EQ(of_rule(lint_text(axis + "net f " + dev("fault.overtemp") + "\n"), "faults-unconnected").size(),
            1u);
  // One fault pin (or its -not twin) netted to something is enough.
  EXPECT_TRUE(
      of_rule(lint_text(axis + "net f " + dev("fault.overtemp-not") + " and2.0.in0\n"), "faults-unconnected")
          .empty());
}

TEST(HalLint, HallPatternThatCommissioningContradicts) {
  const std::string text = "loadrt bldc cfg=qh,h,q\nsetp bldc.0.pattern 17\n";
  const auto f = of_rule(lint_text(text, {std::nullopt, 17}), "hall-pattern");
  // bldc.0 has 17; bldc.1 keeps the default 25 (reported on its load line); bldc.2 has no Halls.
  ASSERT_EQ(lines(f), std::vector<int>{1});
  EXPECT_NE(f[0].message.find("bldc.1.pattern is 25 (its default)"), std::string::npos);
  EXPECT_TRUE(of_rule(lint_text(text), "hall-pattern").empty());  // no --pattern: no rule
}

TEST(HalLint, DoubleDotIsAMalformedName) {
  const auto f =
      of_rule(lint_text("net x-angle bldc.0.phase-angle hm2_7i96s.0.8i20.0.0..angle\n"), "malformed-name");
  ASSERT_EQ(lines(f), std::vector<int>{1});
  EXPECT_EQ(f[0].fix, "write hm2_7i96s.0.8i20.0.0.angle");
}

TEST(HalLint, PidThatNothingDrives) {
  const std::string chain = "loadrt pid num_chan=1\nnet c pid.0.output " + dev("current") +
                            "\nnet x-pos-cmd pid.0.command\nnet x-enable pid.0.enable " + dev("amp_enable") +
                            "\n";
  const auto f = of_rule(lint_text(chain), "pid-input");
  // command: alone on its signal; enable: only with the obsolete amp_enable; feedback: on no signal.
  ASSERT_EQ(lines(f), (std::vector<int>{2, 3, 4}));
  EXPECT_NE(f[0].message.find("pid.0.feedback is connected to nothing"), std::string::npos);
}

TEST(HalLint, FindingsPrintAsFileLineSeverityMessageFix) {
  const auto f = lint_text("setp " + dev("max_current") + " 30\n");
  ASSERT_FALSE(f.empty());
  EXPECT_EQ(
      to_string(f[0]).rfind("t.hal:1: error: " + dev("max_current") + ": the 8I20 param 'max_current'", 0),
      0u);
  EXPECT_NE(to_string(f[0]).find(" (fix: delete it, `current` is in amps"), std::string::npos);
}
