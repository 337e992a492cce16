// SPDX-License-Identifier: GPL-2.0-or-later
// The fault-injection switches: each one must visibly misbehave, reproducibly.
#include <filesystem>
#include <fstream>

#include "bench.hpp"
#include "sim/bits.hpp"
#include "sim/ground_truth.hpp"

namespace i20::sim::test {
namespace {

lbp::Bytes cookies(int n) {
  lbp::Bytes out;
  for (int i = 0; i < n; ++i) out = cat({out, framed("DF")});
  return out;
}

TEST(SimInjection, CorruptEveryReplyByte) {
  DeviceOptions o;
  o.injection.corrupt_rate = 1.0;
  Bench b(o);
  const auto out = b.send("45 74 08");
  const auto clean = reply("20 E1");
  ASSERT_EQ(out.size(), clean.size()) << "corruption changes bytes, not lengths";
  for (std::size_t i = 0; i < out.size(); ++i) EXPECT_NE(out[i], clean[i]) << i;
}

TEST(SimInjection, CorruptionIsReproducibleFromTheSeed) {
  DeviceOptions o;
  o.injection.corrupt_rate = 0.3;
  o.injection.seed = 42;
  Bench a(o), b(o);
  const auto wire = cookies(50);
  const auto out_a = a.raw(wire);
  EXPECT_EQ(out_a, b.raw(wire));
  EXPECT_NE(out_a, Bench().raw(wire)) << "some bytes were corrupted";
  o.injection.seed = 43;
  Bench c(o);
  EXPECT_NE(out_a, c.raw(wire));
}

TEST(SimInjection, DroppedRepliesStillExecute) {
  DeviceOptions o;
  o.injection.drop_rate = 1.0;
  Bench b(o);
  EXPECT_TRUE(b.write16(0x3000, 0xBEEF).empty());
  EXPECT_EQ(b.card.amplifier().ram(0x3000), 0xEF);
  EXPECT_EQ(b.card.stats().replies_dropped, 1u);
}

TEST(SimInjection, DropRateLosesSomeReplies) {
  DeviceOptions o;
  o.injection.drop_rate = 0.5;
  o.injection.seed = 7;
  Bench b(o);
  const auto out = b.raw(cookies(100));
  EXPECT_GT(out.size(), 20u);
  EXPECT_LT(out.size(), 180u);
  EXPECT_EQ(out.size() % 2, 0u);
}

TEST(SimInjection, DelayedReplies) {
  DeviceOptions o;
  o.injection.reply_delay = 5ms;
  Bench b(o);
  EXPECT_TRUE(b.send("DF").empty());
  EXPECT_EQ(b.card.next_event(), b.t + 5ms);
  EXPECT_TRUE(b.wait(4ms).empty());
  EXPECT_EQ(b.wait(1ms), reply("5A"));
}

TEST(SimInjection, ResetInTheMiddleOfABatch) {
  DeviceOptions o;
  o.injection.reset_after_commands = 2;
  Bench b(o);
  EXPECT_EQ(b.raw(cookies(5)), cat({reply("5A"), reply("5A")})) << "two answered, the rest lost";
  b.wait(5ms);
  const auto st = b.read("STATUS");
  EXPECT_TRUE(st & status::kDspWatchdogReset) << "an unexpected reset shows as a DSP watchdog reset";
  EXPECT_EQ(b.send("DF"), reply("5A")) << "one-shot: the card works again";
}

// The soak's judge tells a reset the host could have seen (it sent bytes after it) from
// one right after the reply to its last command, which no tool can see.
TEST(SimInjection, GroundTruthSaysWhetherTheHostSpokeAfterAReset) {
  DeviceOptions o;
  o.injection.reset_after_commands = 1;
  Bench b(o);
  EXPECT_FALSE(capture(b.card).quiet_since_reset) << "no reset yet";
  EXPECT_EQ(b.send("DF"), reply("5A")) << "answered, then reset";
  EXPECT_EQ(capture(b.card).resets, 1u);
  EXPECT_TRUE(capture(b.card).quiet_since_reset) << "nothing sent since the reset";
  b.send("DF");  // lost or not, the host spoke after the reset
  EXPECT_FALSE(capture(b.card).quiet_since_reset);
}

TEST(SimInjection, ReloadedByResetMeansTheNvTwinsValue) {
  Bench b;
  const auto truth = capture(b.card);
  const auto& map = b.card.amplifier().map();
  EXPECT_TRUE(reloaded_by_reset(map, map.at("BRAKEOFFV"), truth))
      << "at power-up the working set is the NV set";
  b.write16(b.address_of("BRAKEOFFV"),
            static_cast<std::uint16_t>(value_in(truth, map.at("NVBRAKEOFFV")) - 100));
  EXPECT_FALSE(reloaded_by_reset(map, map.at("BRAKEOFFV"), capture(b.card)));
}

TEST(SimInjection, ClearfaultStuck) {
  DeviceOptions o;
  o.injection.clearfault_stuck = true;
  o.world.enable = false;
  Bench b(o);
  b.card.world().settings().enable = true;
  b.write16(b.address_of("CLEARFAULT"), 1);
  b.wait(100ms);
  EXPECT_EQ(b.read("CLEARFAULT"), 1u);
  EXPECT_EQ(b.read("FAULT"), fault::kNoEnable);
  b.card.injection().clearfault_stuck = false;
  b.wait(10ms);
  EXPECT_EQ(b.read("CLEARFAULT"), 0u);
  EXPECT_EQ(b.read("FAULT"), 0u);
}

class SimPowerLoss : public ::testing::Test {
 protected:
  void SetUp() override {
    path_ = std::filesystem::temp_directory_path() / ("i20sim-powerloss-" + std::to_string(::getpid()));
    std::filesystem::remove(path_);
  }
  void TearDown() override { std::filesystem::remove(path_); }
  lbp::Bytes image() {
    std::ifstream in(path_, std::ios::binary);
    return lbp::Bytes(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  DeviceOptions options(EepromPowerLoss loss) {
    DeviceOptions o;
    o.eeprom_file = path_;
    o.injection.eeprom_power_loss = loss;
    return o;
  }
  std::filesystem::path path_;
};

TEST_F(SimPowerLoss, TornWriteLandsOnlyTheFirstByte) {
  Bench b(options(EepromPowerLoss::Torn));
  b.send("EC 01");
  EXPECT_TRUE(b.write16(2, 0x1234).empty()) << "no reply: the card lost power";
  EXPECT_FALSE(b.card.powered());
  EXPECT_TRUE(b.wait(10ms).empty());
  EXPECT_TRUE(b.send("DF").empty()) << "a dead card answers nothing";
  const auto img = image();
  EXPECT_EQ(img[2], 0x34);
  EXPECT_EQ(img[3], 0x03) << "the high byte kept its old value (1000 = 0x03E8)";
  b.card.power_cycle(b.t);
  EXPECT_EQ(b.read("MAXCURRENT"), 0x0334u) << "the torn value is what the card wakes up with";
}

TEST_F(SimPowerLoss, LostWriteLeavesTheOldValue) {
  Bench b(options(EepromPowerLoss::Lost));
  b.send("EC 01");
  EXPECT_TRUE(b.write16(2, 0x1234).empty());
  b.card.power_cycle(b.t);
  EXPECT_EQ(b.read("MAXCURRENT"), 1000u);
  b.send("EC 01");
  b.write16(2, 0x1234);
  EXPECT_EQ(b.wait(2ms), lbp::Bytes{0x00}) << "one-shot: the next write works";
}

TEST(SimInjection, MuteAfterNCommands) {
  DeviceOptions o;
  o.injection.answer_limit = 2;
  Bench b(o);
  EXPECT_EQ(b.raw(cookies(4)).size(), 4u);
  EXPECT_TRUE(b.write16(0x3000, 1).empty());
  EXPECT_EQ(b.card.amplifier().ram(0x3000), 0) << "a silent card executes nothing";
  b.card.injection().answer_limit.reset();
  EXPECT_EQ(b.send("DF"), reply("5A"));
}

TEST(SimInjection, SwitchesChangeWhileRunning) {
  Bench b;
  EXPECT_EQ(b.send("DF"), reply("5A"));
  Injection inj;
  inj.drop_rate = 1.0;
  b.card.set_injection(inj);
  EXPECT_TRUE(b.send("DF").empty());
  b.card.set_injection({});
  EXPECT_EQ(b.send("DF"), reply("5A"));
}

}  // namespace
}  // namespace i20::sim::test
