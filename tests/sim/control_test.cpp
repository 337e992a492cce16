// SPDX-License-Identifier: GPL-2.0-or-later
// The control language of i20sim's stdin/FIFO and SimStream::control().
#include "sim/control.hpp"

#include "bench.hpp"
#include "sim/bits.hpp"
#include "sim/error.hpp"

namespace i20::sim::test {
namespace {

TEST(SimControl, WorldCommands) {
  Bench b;
  EXPECT_EQ(apply_control(b.card, "busv 48.5", b.t), "ok");
  EXPECT_EQ(b.read("BUSV"), 4850u);
  EXPECT_EQ(apply_control(b.card, "temp 45", b.t), "ok");
  EXPECT_EQ(b.read("TEMPERATURE"), 4500u);
  EXPECT_EQ(apply_control(b.card, "enable off", b.t), "ok");
  EXPECT_EQ(b.read("FAULT"), fault::kNoEnable);
  EXPECT_EQ(apply_control(b.card, "fault overcurrent on", b.t), "ok");
  EXPECT_EQ(apply_control(b.card, "fault 11 on", b.t), "ok");
  EXPECT_EQ(b.read("FAULT"), fault::kNoEnable | fault::kOverCurrent | fault::kModule);
  apply_control(b.card, "fault overcurrent off", b.t);
  EXPECT_EQ(b.card.world().settings().forced_faults, fault::kModule);
}

TEST(SimControl, NoiseIsBoundedAndSeeded) {
  Bench a, b;
  for (auto* bench : {&a, &b}) {
    apply_control(bench->card, "noise busv 1", bench->t);
    apply_control(bench->card, "seed 9", bench->t);
  }
  bool varied = false;
  const auto first = a.read("BUSV");
  EXPECT_EQ(first, b.read("BUSV"));
  for (int i = 0; i < 20; ++i) {
    const auto v = a.read("BUSV");
    EXPECT_EQ(v, b.read("BUSV")) << "same seed, same samples";
    EXPECT_GE(v, 31900u);
    EXPECT_LE(v, 32100u);
    varied = varied || v != first;
  }
  EXPECT_TRUE(varied);
}

TEST(SimControl, InjectionCommands) {
  Bench b;
  EXPECT_EQ(apply_control(b.card, "drop 1", b.t), "ok");
  EXPECT_TRUE(b.send("DF").empty());
  apply_control(b.card, "drop 0", b.t);
  apply_control(b.card, "delay 3", b.t);
  EXPECT_TRUE(b.send("DF").empty());
  EXPECT_EQ(b.wait(3ms), reply("5A"));
  apply_control(b.card, "delay 0", b.t);
  apply_control(b.card, "corrupt 1", b.t);
  EXPECT_NE(b.send("DF"), reply("5A"));
  apply_control(b.card, "corrupt 0", b.t);
  apply_control(b.card, "mute-after 1", b.t);
  EXPECT_EQ(b.raw(cat({framed("DF"), framed("DF")})), reply("5A"));
  apply_control(b.card, "mute-after off", b.t);
  apply_control(b.card, "reset-after 1", b.t);
  b.send("DF");
  EXPECT_EQ(b.card.stats().resets, 1u);
  apply_control(b.card, "clearfault-stuck on", b.t);
  EXPECT_TRUE(b.card.injection().clearfault_stuck);
  apply_control(b.card, "eeprom-power-loss torn", b.t);
  EXPECT_EQ(b.card.injection().eeprom_power_loss, EepromPowerLoss::Torn);
}

TEST(SimControl, PowerGetSetShow) {
  Bench b;
  EXPECT_EQ(apply_control(b.card, "get SWREVISION", b.t), "57632");  // 0xE120
  EXPECT_EQ(apply_control(b.card, "set maxcurrent 1234", b.t), "ok");
  EXPECT_EQ(b.read("MAXCURRENT"), 1234u);
  apply_control(b.card, "power off", b.t);
  EXPECT_TRUE(b.send("DF").empty());
  EXPECT_NE(apply_control(b.card, "show", b.t).find("power=off"), std::string::npos);
  apply_control(b.card, "power on", b.t);
  EXPECT_EQ(b.send("DF"), reply("5A"));
  const auto shown = apply_control(b.card, "show", b.t);
  EXPECT_NE(shown.find("busv=320.00V"), std::string::npos) << shown;
  EXPECT_NE(shown.find("fault=0x0000"), std::string::npos) << shown;
  EXPECT_EQ(apply_control(b.card, "   # comment only", b.t), "");
  EXPECT_NE(apply_control(b.card, "help", b.t).find("eeprom-power-loss"), std::string::npos);
}

TEST(SimControl, MistakesSayWhatIsExpected) {
  Bench b;
  auto error_of = [&](const char* line) {
    try {
      apply_control(b.card, line, b.t);
    } catch (const ControlError& e) {
      return std::string(e.what());
    }
    return std::string("(no error)");
  };
  EXPECT_NE(error_of("busv").find("busv VOLTS"), std::string::npos);
  EXPECT_NE(error_of("busv lots").find("not a number"), std::string::npos);
  EXPECT_NE(error_of("enable maybe").find("on nor off"), std::string::npos);
  EXPECT_NE(error_of("drop 2").find("0..1"), std::string::npos);
  EXPECT_NE(error_of("fault 16 on").find("0..15"), std::string::npos);
  EXPECT_NE(error_of("frobnicate").find("help"), std::string::npos);
  EXPECT_NE(error_of("get NOSUCH").find("NOSUCH"), std::string::npos);
}

// Fuzz findings (fuzz/regressions/sim_control): "temp nan" reached a uint16 conversion
// (std::clamp lets NaN through) and "delay 1e300" overflowed duration_cast. Numbers must
// be finite, delays within a minute, counts unsigned.
TEST(SimControl, RefusesNumbersThatAreNotFiniteOrInRange) {
  Bench b;
  const auto refused = [&](const char* line) {
    try {
      apply_control(b.card, line, b.t);
    } catch (const ControlError& e) {
      return std::string(e.what());
    }
    return std::string("(accepted)");
  };
  for (const char* line :
       {"temp nan", "temp NAN", "busv inf", "busv -inf", "noise busv nan", "corrupt nan", "drop nan"})
    EXPECT_NE(refused(line).find("not a number"), std::string::npos) << line << ": " << refused(line);
  EXPECT_NE(refused("delay 1e300").find("outside 0..60000"), std::string::npos) << refused("delay 1e300");
  EXPECT_NE(refused("delay -1").find("outside 0..60000"), std::string::npos);
  EXPECT_NE(refused("reset-after -1").find("not a whole number"), std::string::npos) << "stoull wraps -1";
  EXPECT_NE(refused("set MAXCURRENT -5").find("not a whole number"), std::string::npos);
  EXPECT_EQ(b.card.world().settings().temperature_c, 35.0) << "nothing refused changed the world";
  EXPECT_EQ(b.card.injection().reply_delay, Clock::duration::zero());
  EXPECT_EQ(apply_control(b.card, "delay 60000", b.t), "ok");
  EXPECT_EQ(b.card.injection().reply_delay, std::chrono::milliseconds(60000));
  apply_control(b.card, "delay 0", b.t);
  EXPECT_EQ(apply_control(b.card, "temp -20.5", b.t), "ok") << "negative temperatures are fine";
  EXPECT_EQ(b.read("TEMPERATURE"), 0u) << "clamped at the register's 0";
}

}  // namespace
}  // namespace i20::sim::test
