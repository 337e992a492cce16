// SPDX-License-Identifier: GPL-2.0-or-later
// Safety rules of issue 4, enforced in the library: range, confirmation, guards, NV mode.
#include "device/amp.hpp"

#include <gtest/gtest.h>

#include "device/errors.hpp"
#include "lbp/local.hpp"
#include "recording_link.hpp"

using namespace i20;
using namespace i20::device;

namespace {

// The 8I20 client's tries and poll pauses, named here (the programs' are in ops/core/timing.hpp).
constexpr device::AmpTiming kAmpTiming{.leave_mode_tries = 2u,
                                       .reset_poll = std::chrono::milliseconds(20),
                                       .clear_fault_poll = std::chrono::milliseconds(5)};

class AmpTest : public ::testing::Test {
 protected:
  void SetUp() override {
    card.put(2164, *db.simulator_swrevision(), 2);  // SWREVISION
  }
  void identify_as_simulator() { amp.identify(); }
  bool sent_any_write() const {
    for (const auto& c : card.sent)
      if (lbp::kind_of(c.bytes[0]) == lbp::CommandKind::Data && lbp::DataHeader::decode(c.bytes[0]).write)
        return true;
    return false;
  }

  // The client is given the database resolved for the card (ops::Amp does that): here
  // the simulator's revision, whose working map the database confirms.
  static params::ParamDb resolved() {
    const auto loaded = params::ParamDb::builtin();
    return loaded.for_firmware(*loaded.simulator_swrevision());
  }

  test::FakeCard card;
  params::ParamDb db = resolved();
  Amp8i20 amp{card, db, kAmpTiming};
};

}  // namespace

TEST_F(AmpTest, ReadsWorkingParametersByName) {
  card.put(0x082C, 36000, 2);
  EXPECT_EQ(amp.read("BRAKEONV").raw, 36000);
}

TEST_F(AmpTest, NvReadsHappenInsideNvModeAndLeaveIt) {
  card.put(40, 19000, 2, /*nv=*/true);
  EXPECT_EQ(amp.read("NVBRAKEONV").raw, 19000);
  // One exchange: the NV read in NV mode, then a check that the card is still in NV mode
  // (it did not reset meanwhile), then leaving it, and a read that proves it left (0xEC
  // has no reply: only the 0xCC after it shows the card acted on it).
  ASSERT_EQ(card.sent.size(), 5u);
  EXPECT_EQ(card.sent[0].bytes, (lbp::Bytes{0xEC, 0x01}));
  EXPECT_EQ(card.sent[1].bytes, (lbp::Bytes{0x45, 0x28, 0x00}));  // NVBRAKEONV at 40
  EXPECT_EQ(card.sent[2].bytes, (lbp::Bytes{0xCC}));
  EXPECT_EQ(card.sent[3].bytes, (lbp::Bytes{0xEC, 0x00}));
  EXPECT_EQ(card.sent[4].bytes, (lbp::Bytes{0xCC}));
  EXPECT_EQ(card.nv_mode, 0);
}

TEST_F(AmpTest, NvWriteEntersWritesReadsBackAndLeaves) {
  identify_as_simulator();
  card.sent.clear();
  card.exchanges.clear();
  const auto report = amp.write("NVMAXCURRENT", 2500, {});  // manual: "WPD NVMAXCURRENT 2500"
  EXPECT_TRUE(report.verified);
  EXPECT_TRUE(report.needs_reset);
  EXPECT_EQ(card.get(2, 2, true), 2500u);
  EXPECT_EQ(card.get(0x08E8, 2), 0u) << "an NV write changes nothing live (MAXCURRENT, RAM 0x08E8)";
  // Two exchanges: entering NV mode, confirmed in a reply before any EEPROM data write;
  // then the write, its read-back, the mode check, and leaving NV mode (confirmed too).
  ASSERT_EQ(card.sent.size(), 7u);
  EXPECT_EQ(card.sent[0].bytes, (lbp::Bytes{0xEC, 0x01}));
  EXPECT_EQ(card.sent[1].bytes, (lbp::Bytes{0xCC}));
  EXPECT_EQ(card.exchanges.at(0), 2u) << "the data write must not travel with the mode request";
  EXPECT_EQ(card.sent[2].bytes, (lbp::Bytes{0x65, 0x02, 0x00, 0xC4, 0x09}));  // 2-byte write at 2
  EXPECT_TRUE(card.sent[2].barrier);
  EXPECT_EQ(card.sent[3].bytes, (lbp::Bytes{0x45, 0x02, 0x00}));  // read back
  EXPECT_EQ(card.sent[4].bytes, (lbp::Bytes{0xCC}));              // still in NV mode?
  EXPECT_EQ(card.sent[5].bytes, (lbp::Bytes{0xEC, 0x00}));
  EXPECT_EQ(card.sent[6].bytes, (lbp::Bytes{0xCC}));  // and out of it again
}

TEST_F(AmpTest, NvModeIsLeftEvenWhenTheWriteFails) {
  identify_as_simulator();
  card.fail_at = 2;  // enter NV and the mode check succeed, the write times out
  EXPECT_THROW(amp.write("NVBRAKEONV", 32000, {}), link::TimeoutError);
  EXPECT_EQ(card.nv_mode, 0) << "the guard must take the card out of NV mode";
  ASSERT_GE(card.sent.size(), 2u);
  EXPECT_EQ(card.sent[card.sent.size() - 2].bytes, (lbp::Bytes{0xEC, 0x00}));
  EXPECT_EQ(card.sent.back().bytes, (lbp::Bytes{0xCC})) << "and see it confirmed";
}

TEST_F(AmpTest, NvModeIsLeftWhenReadBackDisagrees) {
  identify_as_simulator();
  card.eeprom_stuck = true;
  EXPECT_THROW(amp.write("NVBRAKEONV", 32000, {}), VerifyError);
  EXPECT_EQ(card.nv_mode, 0);
}

TEST_F(AmpTest, AResetInsideAnNvWriteIsNotMistakenForSuccess) {
  identify_as_simulator();
  card.reset_at = 2;  // after entering NV mode and the first mode check, before the write
  // The write then lands in RAM at address 40 and reads back from RAM: equal, but wrong.
  // The mode check after the cell catches it, and says where the value may have gone.
  try {
    amp.write("NVBRAKEONV", 32000, {});
    FAIL() << "a reset inside the EEPROM sequence must not pass as a verified write";
  } catch (const NvModeLost& e) {
    EXPECT_EQ(e.cell(), "NVBRAKEONV");
    EXPECT_EQ(e.address(), 40);
    EXPECT_TRUE(e.stray_ram_value());
    EXPECT_NE(std::string(e.what()).find("working memory at 0x0028"), std::string::npos) << e.what();
  }
  EXPECT_EQ(card.get(40, 2, /*nv=*/true), 0u) << "the EEPROM never got the value";
  EXPECT_EQ(card.get(40, 2), 32000u) << "it went to RAM, which a plain read-back would have 'verified'";
}

TEST_F(AmpTest, AResetInsideAnNvReadIsReportedNotShown) {
  identify_as_simulator();
  card.put(40, 19000, 2, /*nv=*/true);
  card.reset_at = 1;  // right after entering NV mode
  EXPECT_THROW(amp.read("NVBRAKEONV"), AmpStateError);
}

TEST_F(AmpTest, CancelledBeforeAnythingIsSent) {
  std::atomic<bool> cancel{true};
  Amp8i20 cancellable(card, db, kAmpTiming, &cancel);
  EXPECT_THROW(cancellable.write("NVBRAKEONV", 32000, {.allow_unverified = true}), Cancelled);
  EXPECT_TRUE(card.sent.empty());
}

TEST_F(AmpTest, OutOfRangeValuesAreRefusedBeforeAnythingIsSent) {
  identify_as_simulator();
  card.sent.clear();
  EXPECT_THROW(amp.write("NVMAXCURRENT", 3001, {}), SafetyError);
  EXPECT_THROW(amp.write("NVBRAKEONV", 38600, {}), SafetyError);
  EXPECT_THROW(amp.write("QSETPOINT", -40000, {.force = true}), SafetyError);
  EXPECT_TRUE(card.sent.empty());
}

TEST_F(AmpTest, ReadOnlyParametersAreRefused) {
  identify_as_simulator();
  card.sent.clear();
  try {
    amp.write("FAULT", 0, {});
    FAIL();
  } catch (const SafetyError& e) {
    EXPECT_NE(std::string(e.what()).find("CLEARFAULT"), std::string::npos) << e.what();
  }
  EXPECT_THROW(amp.write("BUSV", 0, {}), SafetyError);
  EXPECT_TRUE(card.sent.empty());
}

TEST_F(AmpTest, UnconfirmedWorkingAddressesNeedAllowUnverified) {
  // A real card of a revision the database has no map for.
  const auto other = params::ParamDb::builtin().for_firmware(0x0100);
  Amp8i20 amp{card, other, kAmpTiming};
  card.sent.clear();
  try {
    amp.write("BRAKEONV", 30000, {});
    FAIL();
  } catch (const SafetyError& e) {
    EXPECT_NE(std::string(e.what()).find("not confirmed"), std::string::npos) << e.what();
    // What overrides it is a marker for the app to name in its own words: lib/ names no option.
    EXPECT_EQ(e.advice(), i20::Advice::AllowUnverified);
    EXPECT_EQ(std::string(e.what()).find("--"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(card.sent.empty());
  // NV addresses are public facts: they work on any revision.
  EXPECT_NO_THROW(amp.write("NVBRAKEONV", 30000, {}));
  card.sent.clear();
  EXPECT_NO_THROW(amp.write("BRAKEONV", 30000, {.allow_unverified = true}));
  EXPECT_EQ(card.get(0x082C, 2), 30000u);
}

TEST_F(AmpTest, GuardedParametersNeedForceAndSayWhy) {
  identify_as_simulator();
  card.sent.clear();
  try {
    amp.write("NVBAUDRATE", 4, {});
    FAIL();
  } catch (const SafetyError& e) {
    EXPECT_EQ(e.advice(), i20::Advice::Force);
    EXPECT_EQ(std::string(e.what()).find("--"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("link speed"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(card.sent.empty());
  EXPECT_NO_THROW(amp.write("NVBAUDRATE", 4, {.force = true}));
}

TEST_F(AmpTest, BatchWritesAreAllCheckedBeforeTheFirstIsSent) {
  identify_as_simulator();
  card.sent.clear();
  const std::vector<Assignment> batch{{&db.get("NVBRAKEONV"), 32000}, {&db.get("NVMAXCURRENT"), 9999}};
  EXPECT_THROW(amp.write(batch, {}), SafetyError);
  EXPECT_FALSE(sent_any_write());
  EXPECT_TRUE(card.sent.empty());
}

TEST_F(AmpTest, WorkingWritesAreVerified) {
  identify_as_simulator();
  const auto r = amp.write("BRAKEONV", 30000, {});  // manual: "WPD BRAKEONV 30000" = 300 V
  EXPECT_TRUE(r.verified);
  EXPECT_FALSE(r.needs_reset);
  EXPECT_EQ(card.get(0x082C, 2), 30000u);
}

TEST_F(AmpTest, InfoReadsNameRevisionAndUnitNumber) {
  card.put(2344, 0x00012345, 4);
  const auto info = amp.info();
  EXPECT_EQ(info.card_name, "8I20");
  EXPECT_EQ(info.swrevision, db.simulator_swrevision());
  EXPECT_EQ(info.unit_number, 0x00012345u);
  EXPECT_TRUE(info.working_map_confirmed);
}

TEST_F(AmpTest, ReadMemoryUsesEightByteReadsAndNvGuard) {
  card.put(10, 0x1122334455667788ULL, 8, true);
  card.put(18, 0xAB, 1, true);
  const auto bytes = amp.read_memory(params::Space::Eeprom, 10, 9);
  ASSERT_EQ(bytes.size(), 9u);
  EXPECT_EQ(bytes[0], 0x88);
  EXPECT_EQ(bytes[8], 0xAB);
  EXPECT_EQ(card.nv_mode, 0);
  EXPECT_EQ(card.sent[1].bytes[0], 0x47);  // 8-byte read with address
}
