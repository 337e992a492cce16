// SPDX-License-Identifier: GPL-2.0-or-later
// `i20 hal lint --ini`: the files' INI references against the INI, and the notch i20 pid
// --notch designs run by the files or said not to be.
#include "linuxcnc/ini_check.hpp"

#include <gtest/gtest.h>

#include "hal_plans.hpp"
#include "linuxcnc/hal_generate.hpp"

using namespace i20::linuxcnc;

namespace {

using test::kProgramDelays;

HalPlan one_axis(bool notch) {
  HalPlan p = test::hall_encoder_plan(1);
  p.notch = notch;
  return p;
}

const std::string kBase =
    "[KINS]\nKINEMATICS = trivkins\nJOINTS = 1\n[EMCMOT]\nEMCMOT = motmod\nSERVO_PERIOD = 1000000\n"
    "[JOINT_0]\n# gains\nENCODER_SCALE = 800\nP = 1\nI = 0\nD = 0\nFF0 = 0\nFF1 = 0\nFF2 = 0\n"
    "BIAS = 0\n; no deadband\nDEADBAND = 0\n";
const std::string kNotch =
    "NOTCH_N0 = 0.8\nNOTCH_N1 = -0.7\nNOTCH_N2 = 0.8\nNOTCH_D1 = -0.7\nNOTCH_D2 = 0.63\n";

std::vector<LintFinding> check(bool hal_notch, const std::string& ini) {
  return check_ini(read_hal(generate_hal(one_axis(hal_notch), kProgramDelays), "axis.hal"), ini, "axis.ini");
}

}  // namespace

TEST(IniCheck, TheGeneratedFileWithItsIniIsClean) {
  EXPECT_TRUE(check(false, kBase).empty());
  EXPECT_TRUE(check(true, kBase + kNotch).empty());
}

TEST(IniCheck, AKeyTheFileReadsAndTheIniLacksIsWhereHalcmdStops) {
  const auto findings = check(true, kBase);  // the HAL runs the notch; the INI has none
  ASSERT_EQ(findings.size(), 5u);
  const auto& f = findings.front();
  EXPECT_EQ(f.rule, "ini-missing");
  EXPECT_TRUE(f.refused_by_halcmd);
  EXPECT_EQ(f.at.file, "axis.hal");
  EXPECT_NE(f.message.find("[JOINT_0]NOTCH_N0 is not in axis.ini"), std::string::npos) << f.message;
  EXPECT_EQ(f.fix, "add NOTCH_N0 = VALUE under [JOINT_0] in axis.ini");
}

TEST(IniCheck, ANotchTheFilesDoNotRunIsSaid) {
  const auto findings = check(false, kBase + kNotch);
  ASSERT_EQ(findings.size(), 1u);
  EXPECT_EQ(findings[0].rule, "ini-notch-not-run");
  EXPECT_EQ(findings[0].severity, LintSeverity::Warning);
  EXPECT_EQ(findings[0].at.file, "axis.ini");
  EXPECT_EQ(findings[0].at.line, 19);  // NOTCH_N0's line
  EXPECT_NE(findings[0].fix.find("i20 hal --notch"), std::string::npos);
}
