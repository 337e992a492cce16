// SPDX-License-Identifier: GPL-2.0-or-later
// `i20 hal`'s writer: the file reads as halcmd reads it, passes our own linter with the
// facts it was written from, and is wired the way docs/linuxcnc-hal.md says.
#include "linuxcnc/hal_generate.hpp"

#include <gtest/gtest.h>

#include "error/error.hpp"
#include "hal_plans.hpp"
#include "linuxcnc/hal_design.hpp"
#include "linuxcnc/hal_lint.hpp"

using namespace i20::linuxcnc;

namespace {

using test::hall_encoder_plan;
using test::kProgramDelays;

std::string bad(const HalPlan& p) {
  try {
    check_plan(p);
  } catch (const i20::UsageError& e) {
    return e.what();
  }
  return "accepted";
}

}  // namespace

TEST(HalGenerate, EveryPlanLintsCleanWithTheFactsItWasWrittenFrom) {
  std::vector<HalPlan> plans{hall_encoder_plan(1), hall_encoder_plan(3)};
  auto qhi = hall_encoder_plan(1);
  qhi.cfg = "qhi";
  qhi.encoder_offset = 120;
  qhi.board = "7i92t";
  qhi.estop_in = "hm2_7i92.0.gpio.010.in";
  plans.push_back(qhi);
  HalPlan halls_only;
  halls_only.cfg = "h";
  halls_only.pattern = 25;
  halls_only.max_current = 5.0;
  halls_only.halls = {"a.in,b.in,c.in"};
  plans.push_back(halls_only);
  auto notched = hall_encoder_plan(2);
  notched.notch = true;
  plans.push_back(notched);
  for (const auto& p : plans) {
    const auto text = generate_hal(p, kProgramDelays);
    const auto findings = lint(read_hal(text, "gen.hal"), {p.max_current, p.pattern});
    for (const auto& f : findings)
      ADD_FAILURE() << "cfg=" << p.cfg << " axes=" << p.axes << ": " << to_string(f);
  }
}

TEST(HalGenerate, RotorAngleFeedsTheEightI20AndTheCurrentIsLimitedToMaxcurrent) {
  const HalDesign d(read_hal(generate_hal(hall_encoder_plan(2), kProgramDelays), "gen.hal"));
  for (int k = 0; k < 2; ++k) {
    const std::string n = std::to_string(k), dev = "hm2_7i96s.0.8i20.0." + n;
    const auto* angle = d.signal_of(dev + ".angle");
    ASSERT_NE(angle, nullptr);
    EXPECT_TRUE(std::any_of(angle->pins.begin(), angle->pins.end(),
                            [&](const auto& p) { return p.name == "bldc." + n + ".rotor-angle"; }));
    EXPECT_EQ(d.signal_of("bldc." + n + ".phase-angle"), nullptr);  // never used
    EXPECT_EQ(d.setting("pid." + n + ".maxoutput")->value, "12");
    EXPECT_EQ(d.signal_of("bldc." + n + ".out"), d.signal_of(dev + ".current"));
    EXPECT_EQ(d.signal_of("pid." + n + ".output"), d.signal_of("bldc." + n + ".value"));
    EXPECT_EQ(d.signal_of("hm2_7i96s.0.encoder.0" + n + ".rawcounts"),
              d.signal_of("bldc." + n + ".rawcounts"));
    EXPECT_EQ(d.setting("bldc." + n + ".pattern")->value, "17");
    EXPECT_EQ(d.setting("bldc." + n + ".poles")->value, "8");
    EXPECT_EQ(d.setting("bldc." + n + ".scale")->value, "4000");
    EXPECT_EQ(d.setting("bldc." + n + ".lead-angle"), nullptr);  // not needed with rotor-angle
  }
  EXPECT_EQ(d.module("bldc")->args.at("cfg"), "qh,qh");
  EXPECT_EQ(d.module("hm2_eth")->args.at("board_ip"), "10.10.10.10");
  EXPECT_EQ(d.signal_of("hm2_7i96s.0.sserial.port-0.run"), d.signal_of("i20-port-run.out"));
}

// i20 hal --notch: the pid's output reaches bldc through a biquad per axis, which runs between
// them in the servo thread with the INI's coefficients, type 0, enabled; the linter follows the
// current command through it to the pid's maxoutput.
TEST(HalGenerate, TheNotchSitsBetweenThePidAndBldc) {
  auto plan = hall_encoder_plan(2);
  plan.notch = true;
  const std::string text = generate_hal(plan, kProgramDelays);
  const HalDesign d(read_hal(text, "gen.hal"));
  EXPECT_EQ(d.module("biquad")->args.at("names"), "i20-notch-0,i20-notch-1");
  for (int k = 0; k < 2; ++k) {
    const std::string n = std::to_string(k), notch = "i20-notch-" + n;
    EXPECT_EQ(d.signal_of("pid." + n + ".output"), d.signal_of(notch + ".in"));
    EXPECT_EQ(d.signal_of(notch + ".out"), d.signal_of("bldc." + n + ".value"));
    EXPECT_NE(d.signal_of("pid." + n + ".output"), d.signal_of("bldc." + n + ".value"));
    EXPECT_EQ(d.setting(notch + ".type")->value, "0");
    EXPECT_EQ(d.setting(notch + ".enable")->value, "1");
    EXPECT_EQ(d.setting(notch + ".n0")->value, "[JOINT_" + n + "]NOTCH_N0");
    EXPECT_EQ(d.setting(notch + ".d2")->value, "[JOINT_" + n + "]NOTCH_D2");
    const auto pid_at = text.find("addf pid." + n + ".do-pid-calcs"),
               notch_at = text.find("addf " + notch + " ");
    EXPECT_LT(pid_at, notch_at);
    EXPECT_LT(notch_at, text.find("addf bldc." + n + " "));
  }
  EXPECT_NE(text.find("[JOINT_k]NOTCH_N0"), std::string::npos) << "the header names the INI values";
  const auto findings = lint(read_hal(text, "gen.hal"), {6.0, plan.pattern});  // MAXCURRENT 6 < 12
  EXPECT_TRUE(std::any_of(findings.begin(), findings.end(), [](const LintFinding& f) {
    return f.rule == "current-above-max" && f.message.find("pid.0") != std::string::npos;
  })) << "the limit is followed through the notch to pid.0";
  EXPECT_EQ(generate_hal(hall_encoder_plan(1), kProgramDelays).find("biquad"), std::string::npos);
}

TEST(HalGenerate, EveryFaultPinOfEveryEightI20ReachesTheEstopChain) {
  const HalDesign d(read_hal(generate_hal(hall_encoder_plan(2), kProgramDelays), "gen.hal"));
  const auto& faults = HalNames::builtin().i20_fault_pins();
  // logic personalities: per axis `or` over 13 inputs, `nand` of that and the watch, `and` of
  // the enable and the watch; the link's `nor` of 2; the chain: `and` of 4.
  EXPECT_EQ(d.module("logic")->args.at("personality"), "0x20D,0x802,0x102,0x20D,0x802,0x102,0x1002,0x104");
  for (int k = 0; k < 2; ++k) {
    const std::string n = std::to_string(k);
    for (std::size_t i = 0; i < faults.size(); ++i) {
      const auto* sig = d.signal_of("hm2_7i96s.0.8i20.0." + n + "." + faults[i]);
      ASSERT_NE(sig, nullptr) << faults[i];
      EXPECT_EQ(sig, d.signal_of("i20-faults-" + n + ".in-" + (i < 10 ? "0" : "") + std::to_string(i)));
    }
    EXPECT_EQ(d.signal_of("i20-faults-" + n + ".or"), d.signal_of("i20-ok-" + n + ".in-00"));
    EXPECT_EQ(d.signal_of("i20-ok-" + n + ".in-01"), d.signal_of("i20-watching.out"));
    EXPECT_EQ(d.signal_of("i20-ok-" + n + ".nand"), d.signal_of("i20-estop-ok.in-0" + std::to_string(k + 1)));
  }
  // The link's own failure: hm2_eth's packet errors past their limit.
  EXPECT_EQ(d.signal_of("hm2_7i96s.0.packet-error-exceeded"), d.signal_of("i20-link-ok.in-00"));
  // ... and a port hostmot2 stopped for its errors: its fault-count past fault-lim, the same
  // limit on both sides.
  EXPECT_EQ(d.signal_of("hm2_7i96s.0.sserial.port-0.fault-count"), d.signal_of("i20-port-errors.in"));
  EXPECT_EQ(d.signal_of("i20-port-errors.out"), d.signal_of("i20-port-stopped.in1"));
  EXPECT_EQ(d.setting("hm2_7i96s.0.sserial.port-0.fault-lim")->value,
            d.setting("i20-port-stopped.in0")->value);
  EXPECT_EQ(d.signal_of("i20-port-stopped.out"), d.signal_of("i20-link-ok.in-01"));
  EXPECT_EQ(d.signal_of("i20-link-ok.nor"), d.signal_of("i20-estop-ok.in-03"));
  EXPECT_EQ(d.signal_of("i20-estop-ok.and"), d.signal_of("iocontrol.0.emc-enable-in"));
  // No E-stop input given: the chain's first input is left for the user, so E-stop holds.
  const auto* ext = d.signal_of("i20-estop-ok.in-00");
  ASSERT_NE(ext, nullptr);
  EXPECT_EQ(ext->pins.size(), 1u);
}

// The power-up (docs/linuxcnc-hal.md, "Power-up and fault reset"): the port runs a second
// after machine-on (the bus has risen; machine off then on restarts it, which clears latched
// faults), its 8I20s' faults count and the pids are enabled half a second after that.
// LinuxCNC runs it in tests/linuxcnc_axis/axis_test.sh.
TEST(HalGenerate, ThePortRunsAfterMachineOnAndItsFaultsCountOnlyOnceItRuns) {
  const auto text = generate_hal(hall_encoder_plan(2), kProgramDelays);
  const HalDesign d(read_hal(text, "gen.hal"));
  EXPECT_EQ(d.signal_of("motion.motion-enabled"), d.signal_of("i20-port-run.in"));
  EXPECT_EQ(d.signal_of("i20-port-run.out"), d.signal_of("hm2_7i96s.0.sserial.port-0.run"));
  EXPECT_EQ(d.signal_of("i20-port-run.out"), d.signal_of("i20-watching.in"));
  EXPECT_EQ(d.setting("i20-port-run.on-delay")->value, "1");
  EXPECT_EQ(d.setting("i20-port-run.off-delay")->value, "0");
  EXPECT_EQ(d.setting("i20-watching.on-delay")->value, "0.5");
  EXPECT_EQ(d.setting("hm2_7i96s.0.sserial.port-0.run"), nullptr) << "run follows the machine, not a setp";
  for (int k = 0; k < 2; ++k) {
    const std::string n = std::to_string(k);
    EXPECT_EQ(d.signal_of("joint." + n + ".amp-enable-out"), d.signal_of("i20-enable-" + n + ".in-00"));
    EXPECT_EQ(d.signal_of("i20-watching.out"), d.signal_of("i20-enable-" + n + ".in-01"));
    EXPECT_EQ(d.signal_of("i20-enable-" + n + ".and"), d.signal_of("pid." + n + ".enable"));
  }
  // The timers and gates run after the board's read and before the pids.
  EXPECT_LT(text.find("addf hm2_7i96s.0.read"), text.find("addf i20-port-run"));
  EXPECT_LT(text.find("addf i20-estop-ok"), text.find("addf pid.0.do-pid-calcs"));
}

TEST(HalGenerate, QhiNetsTheIndexBetweenEncoderAndBldcOnly) {
  auto p = hall_encoder_plan(1);
  p.cfg = "qhi";
  p.encoder_offset = -250;
  const HalDesign d(read_hal(generate_hal(p, kProgramDelays), "gen.hal"));
  const auto* index = d.signal_of("bldc.0.index-enable");
  ASSERT_NE(index, nullptr);
  EXPECT_EQ(index, d.signal_of("hm2_7i96s.0.encoder.00.index-enable"));
  EXPECT_EQ(d.signal_of("joint.0.index-enable"), nullptr);
  EXPECT_EQ(d.setting("bldc.0.encoder-offset")->value, "-250");
}

// bldc stores the index from its rawcounts input in the period it finds index-enable false, a
// read after the card latched it: the file hands bldc rawcounts - count (hostmot2 resets
// count at the latched index) in that one period and rawcounts in every other
// (docs/linuxcnc-hal.md, "The index under bldc"). LinuxCNC runs it in
// tests/linuxcnc_axis/commission_test.sh.
TEST(HalGenerate, QhiHandsBldcTheLatchedIndexThroughTheCapture) {
  auto p = hall_encoder_plan(2);
  p.cfg = "qhi";
  p.encoder_offset = 40;
  const auto text = generate_hal(p, kProgramDelays);
  const HalDesign d(read_hal(text, "gen.hal"));
  for (int k = 0; k < 2; ++k) {
    const std::string n = std::to_string(k), j = "j" + n + "-", mux = "mux-gen.0" + n;
    const std::string encoder = "hm2_7i96s.0.encoder.0" + n;
    SCOPED_TRACE("axis " + n);
    ASSERT_NE(d.signal_of("bldc." + n + ".rawcounts"), nullptr);
    EXPECT_EQ(d.signal_of("bldc." + n + ".rawcounts"), d.signal_of(mux + ".out-s32"));
    EXPECT_EQ(d.signal_of(mux + ".in-s32-00"), d.signal_of(encoder + ".rawcounts"));
    EXPECT_EQ(d.signal_of(mux + ".in-s32-01"), d.signal_of(j + "index-count.out-s"));
    EXPECT_EQ(d.signal_of(j + "index-count.in0"), d.signal_of(encoder + ".rawcounts"));
    EXPECT_EQ(d.signal_of(j + "index-count.in1"), d.signal_of(encoder + ".count"));
    EXPECT_EQ(d.setting(j + "index-count.scale1")->value, "-1");
    EXPECT_EQ(d.signal_of(mux + ".sel-bit-00"), d.signal_of(j + "index-seen.out"));
    EXPECT_EQ(d.signal_of(j + "index-seen.in"), d.signal_of("bldc." + n + ".index-enable"));
    EXPECT_EQ(d.setting(j + "index-seen.in-edge")->value, "true");
    // After the board's read, before bldc.
    const auto read = text.find("addf hm2_7i96s.0.read servo-thread");
    const auto edge = text.find("addf " + j + "index-seen servo-thread");
    const auto sum = text.find("addf " + j + "index-count servo-thread");
    const auto select = text.find("addf " + mux + " servo-thread");
    const auto bldc = text.find("addf bldc." + n + " servo-thread");
    ASSERT_NE(bldc, std::string::npos);
    EXPECT_LT(read, edge);
    EXPECT_LT(edge, sum);
    EXPECT_LT(sum, select);
    EXPECT_LT(select, bldc);
  }
  EXPECT_NE(text.find("loadrt mux_generic config=\"ss2,ss2\"\n"), std::string::npos) << text;
  // Without an index bldc reads rawcounts itself: no capture.
  const auto qh = generate_hal(hall_encoder_plan(1), kProgramDelays);
  EXPECT_EQ(qh.find("mux_generic"), std::string::npos);
  EXPECT_NE(qh.find("net j0-rawcounts hm2_7i96s.0.encoder.00.rawcounts => bldc.0.rawcounts\n"),
            std::string::npos);
}

TEST(HalGenerate, TheHeaderNamesTheIniValuesItReads) {
  const auto text = generate_hal(hall_encoder_plan(1), kProgramDelays);
  for (const char* ini :
       {"[KINS]KINEMATICS", "[EMCMOT]SERVO_PERIOD", "[JOINT_k]ENCODER_SCALE", "FF0", "DEADBAND"})
    EXPECT_NE(text.find(ini), std::string::npos) << ini;
  EXPECT_NE(text.find("setp pid.0.Pgain [JOINT_0]P\n"), std::string::npos);
  EXPECT_NE(text.find("setp hm2_7i96s.0.encoder.00.scale [JOINT_0]ENCODER_SCALE\n"), std::string::npos);
}

TEST(HalGenerate, RefusesPlansItCannotWriteCorrectly) {
  auto p = hall_encoder_plan(1);
  EXPECT_EQ(bad(p), "accepted");
  auto q = p;
  q.cfg = "qi";
  EXPECT_NE(bad(q).find("--cfg qi: i20 hal writes qh, qhi or h"), std::string::npos);
  q = p;
  q.pattern = 48;
  EXPECT_EQ(bad(q), "--pattern 48: bldc's Hall patterns are 0 to 47");
  q = p;
  q.pattern.reset();
  EXPECT_NE(bad(q).find("--pattern is required"), std::string::npos);
  q = p;
  q.poles = 7;
  EXPECT_NE(bad(q).find("--poles 7"), std::string::npos);
  q = p;
  q.counts_per_rev.reset();
  EXPECT_NE(bad(q).find("--counts-per-rev is required"), std::string::npos);
  q = p;
  q.encoder_offset = 5;
  EXPECT_EQ(bad(q), "--encoder-offset needs a cfg with i: bldc cfg=qh creates no encoder-offset");
  q = p;
  q.max_current.reset();
  EXPECT_NE(bad(q).find("--max-current (or --profile) is required"), std::string::npos);
  q = p;
  q.max_current = 31;  // the 8I20's MAXCURRENT is at most 30 A (params/8i20.yaml)
  EXPECT_NE(bad(q).find("at most 30 A"), std::string::npos);
  q = p;
  q.board = "7i76e";
  EXPECT_EQ(bad(q), "--board 7i76e: 7i96s or 7i92t");
  q = p;
  q.board_ip = "10.10.10";
  EXPECT_NE(bad(q).find("not an IPv4 address"), std::string::npos);
  q = p;
  q.halls = {"a.in,b.in"};
  EXPECT_NE(bad(q).find("three pins"), std::string::npos);
  q = p;
  q.halls = {"a.in,b..in,c.in"};
  EXPECT_NE(bad(q).find("'b..in' is not a HAL pin name"), std::string::npos);
  q = p;
  q.axes = 9;
  EXPECT_NE(bad(q).find("--axes 9: 1 to 8"), std::string::npos);
  for (const auto& message : {bad(q)}) EXPECT_EQ(message.find('\n'), std::string::npos);  // one line
}
