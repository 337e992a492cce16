// SPDX-License-Identifier: GPL-2.0-or-later
// `i20 hal lint --load`'s pure half: which virtual card the files need, which lines only a
// running LinuxCNC can load (left out line for line, so halcmd's line numbers are the
// file's), and halcmd's messages read back onto the files.
#include "linuxcnc/hal_load.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

using namespace i20::linuxcnc;

namespace {

HalSource source(const std::string& file, const std::string& text) {
  return {file, text, read_hal(text, file)};
}

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::size_t begin = 0;
  for (std::size_t end; (end = text.find('\n', begin)) != std::string::npos; begin = end + 1)
    out.push_back(text.substr(begin, end - begin));
  return out;
}

std::string plan_error(const std::vector<HalSource>& sources) {
  try {
    plan_load(sources);
  } catch (const i20::UsageError& e) {
    return e.what();
  }
  return "(planned)";
}

const std::string kAxis =
    "loadrt [KINS]KINEMATICS\n"
    "loadrt [EMCMOT]EMCMOT servo_period_nsec=[EMCMOT]SERVO_PERIOD num_joints=[KINS]JOINTS\n"
    "loadrt hostmot2\n"
    "loadrt hm2_eth board_ip=\"10.10.10.10\"\n"
    "net j1-cur bldc.1.out => hm2_7i92.0.8i20.0.1.current\n"
    "loadusr -W hal_manualtoolchange\n"
    "net tool-change iocontrol.0.tool-change => \\\n"
    "    hal_manualtoolchange.change\n"
    "net tool-prep-loop iocontrol.0.tool-prepare iocontrol.0.tool-prepared\n"
    "net spindle hm2_7i92.0.encoder.01.velocity\n";

}  // namespace

TEST(HalLoad, TheFilesNameTheCardItsAddressAndItsEightI20s) {
  const auto plan = plan_load({source("axis.hal", kAxis)});
  EXPECT_EQ(plan.need.card, "7i92t-servo");
  EXPECT_EQ(plan.need.board_ip, "10.10.10.10") << "quotes removed";
  EXPECT_EQ(plan.need.channels, 2) << "channel 1 is used";
  EXPECT_TRUE(plan.need.motion);
  EXPECT_TRUE(plan.need.ini);
}

TEST(HalLoad, WhatOnlyARunningLinuxcncLoadsIsLeftOutLineForLine) {
  const auto plan = plan_load({source("axis.hal", kAxis)});
  const auto in = lines(kAxis);
  const auto out = lines(plan.loadable.at(0));
  ASSERT_EQ(out.size(), in.size()) << "halcmd's line numbers must stay the file's";
  for (std::size_t i = 0; i < in.size(); ++i) {
    const bool left_out = i >= 5 && i <= 8;  // loadusr, the continued net (two lines), iocontrol
    EXPECT_EQ(out[i], left_out ? "#" + in[i] : in[i]) << "line " << i + 1;
  }
  ASSERT_EQ(plan.left_out.size(), 3u);
  EXPECT_EQ(plan.left_out[0].rfind("axis.hal:6: loadusr", 0), 0u) << plan.left_out[0];
  EXPECT_NE(plan.left_out[1].find("axis.hal:7: names iocontrol's pins"), std::string::npos)
      << plan.left_out[1];
}

TEST(HalLoad, RefusesWhatNoVirtualCardCanRun) {
  EXPECT_NE(plan_error({source("a.hal", "loadrt hostmot2\n")}).find("load no hm2_eth board"),
            std::string::npos);
  EXPECT_NE(plan_error({source("a.hal", "loadrt hm2_pci\n")}).find("a.hal:1: loadrt hm2_pci"),
            std::string::npos);
  EXPECT_NE(
      plan_error({source("a.hal", "loadrt hm2_eth board_ip=10.0.0.1,10.0.0.2\n")}).find("several boards"),
      std::string::npos);
  EXPECT_NE(plan_error({source("a.hal", "loadrt hm2_eth\n")}).find("without board_ip"), std::string::npos);
  EXPECT_NE(
      plan_error({source("a.hal", "loadrt hm2_eth board_ip=10.0.0.1\nnet x hm2_7i96s.0.8i20.0.1.angle\n")})
          .find("channel 1 on a 7I96S"),
      std::string::npos);
}

TEST(HalLoad, HalcmdMessagesLandOnTheFilesTheCopiesStandFor) {
  const std::string output =
      "Note: Using POSIX non-realtime\n"
      "/tmp/x/0-axis.hal:10: Pin 'hm2_7i92.0.encoder.01.velocity' does not exist\n"
      "/tmp/x/1-post.hal:3: parameter or pin 'foo.bar' not found\n"
      "hm2_eth: no board at 10.10.10.10\n"
      "/tmp/elsewhere.hal:2: something\n";
  const auto r =
      read_halrun_output(output, {{"/tmp/x/0-axis.hal", "axis.hal"}, {"/tmp/x/1-post.hal", "post.hal"}});
  ASSERT_EQ(r.findings.size(), 2u);
  EXPECT_EQ(to_string(r.findings[0])
                .rfind("axis.hal:10: error: halcmd: Pin 'hm2_7i92.0.encoder.01.velocity' does "
                       "not exist",
                       0),
            0u)
      << to_string(r.findings[0]);
  EXPECT_EQ(r.findings[1].at.file, "post.hal");
  EXPECT_EQ(r.findings[1].at.line, 3);
  EXPECT_EQ(r.other, (std::vector<std::string>{"hm2_eth: no board at 10.10.10.10",
                                               "/tmp/elsewhere.hal:2: something"}));
}

// LinuxCNC's realtime not starting is said as such, never as a finding on a line of the file.
TEST(HalLoad, RealtimeThatDidNotStartIsNoFinding) {
  const auto r = read_halrun_output("/tmp/x/0-axis.hal:4: /usr/bin/rtapi_app exited without becoming ready\n",
                                    {{"/tmp/x/0-axis.hal", "axis.hal"}});
  EXPECT_TRUE(r.findings.empty());
  EXPECT_TRUE(r.realtime_failed);
}

// What is quoted of a realtime that did not start is why (the lines up to the first naming
// rtapi_app), not the unloading after it.
TEST(HalLoad, RealtimeThatDidNotStartIsQuotedAtItsCause) {
  const auto r = read_halrun_output(
      "Note: Using POSIX realtime\nhm2_eth: loading\nhm2_eth: timeout reading the IDROM\n"
      "/tmp/x/0-axis.hal:2: waitpid failed /usr/bin/rtapi_app hm2_eth\n"
      "hm2_eth: in hm2_eth_reset\nhm2: unloading\nrtapi_app: exit\n",
      {{"/tmp/x/0-axis.hal", "axis.hal"}});
  EXPECT_TRUE(r.realtime_failed);
  EXPECT_EQ(r.realtime_why,
            (std::vector<std::string>{"hm2_eth: loading", "hm2_eth: timeout reading the IDROM",
                                      "/tmp/x/0-axis.hal:2: waitpid failed /usr/bin/rtapi_app hm2_eth"}));
}

// A line both the lint and halcmd refuse (an INI key missing) is one finding, in the lint's
// words with its fix; halcmd's complaints about other lines are added.
TEST(HalLoad, ALineTheLintFoundRefusedIsNotReportedAgainInHalcmdsWords) {
  // Built field by field: GCC 12 at -O3 takes a braced list of these for uninitialized.
  std::vector<LintFinding> findings(2);
  findings[0].at = {"axis.hal", 7};
  findings[0].rule = "ini-missing";
  findings[0].refused_by_halcmd = true;
  findings[1].at = {"axis.hal", 9};
  findings[1].severity = LintSeverity::Warning;
  findings[1].rule = "pid-maxoutput";
  const auto halrun = read_halrun_output(
      "/tmp/x/0-axis.hal:7: Ini variable '[JOINT_0]P' not found.\n"
      "/tmp/x/0-axis.hal:9: Pin 'pid.0.maxoutput' does not exist\n"
      "/tmp/x/0-axis.hal:12: Pin 'foo.bar' does not exist\n",
      {{"/tmp/x/0-axis.hal", "axis.hal"}});
  ASSERT_EQ(halrun.findings.size(), 3u);
  add_halrun_findings(findings, halrun.findings);
  ASSERT_EQ(findings.size(), 4u);
  EXPECT_EQ(findings[0].rule, "ini-missing");
  EXPECT_EQ(std::count_if(findings.begin(), findings.end(), [](const auto& f) { return f.at.line == 7; }), 1);
  // A warning on a line is no refusal: halcmd's own words about that line are kept.
  EXPECT_EQ(std::count_if(findings.begin(), findings.end(), [](const auto& f) { return f.at.line == 9; }), 2);
  EXPECT_EQ(findings.back().at.line, 12);
  EXPECT_EQ(findings.back().rule, "halrun");
}
