// SPDX-License-Identifier: GPL-2.0-or-later
// Issue 10's reproductions, each against the in-process simulator with the same injection,
// through the same use cases the programs call (lib/ops). Every verdict comes from the
// simulator's own memory, not from what the tool reports.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <optional>

#include "device/errors.hpp"
#include "lbp/header.hpp"
#include "ops/apply_run.hpp"
#include "ops/change.hpp"
#include "ops/core/read.hpp"
#include "ops/discover.hpp"
#include "ops/faults.hpp"
#include "sim_rig.hpp"

using namespace i20;
using namespace i20::ops;
using namespace i20::ops::testing;

namespace {

struct SetResult {
  TargetRun run;
  std::string refused;  // precheck refusal (nothing opened), if any
};

// `i20 set A=1 B=2` (or `wpd NAME VALUE` with raw syntax) on an open card, as the apps run it.
SetResult set(Amp& amp, const std::vector<std::string>& assignments,
              ValueSyntax syntax = ValueSyntax::Engineering, device::WriteOptions write = {},
              Cancel cancel = {}) {
  SetResult r;
  try {
    const ValueChange change({.values = named_values(assignments),
                              .syntax = syntax,
                              .force = write.force,
                              .allow_unverified = write.allow_unverified,
                              .cancel = cancel},
                             amp.db());
    r.run = change.run_on(amp);
  } catch (const device::SafetyError& e) {
    r.refused = e.what();  // judged before anything was sent
  }
  return r;
}

std::string reason(const SetResult& r) {
  return r.refused.empty() ? r.run.result->reason : r.refused;
}

bool refused(const SetResult& r) {
  return !r.refused.empty() || r.run.outcome == Outcome::Refused;
}

}  // namespace

// ---------------------------------------------------------------- the manual's rules on every path
TEST(OpsRules, BrakeOffAboveTheCardsBrakeOnIsRefusedOnSetAndWpd) {
  SimRig rig;
  auto amp = rig.open();
  const auto before = rig.truth();
  auto r = set(*amp, {"NVBRAKEOFFV=370V"});  // NVBRAKEONV is 360 V on the card
  EXPECT_TRUE(refused(r));
  EXPECT_NE(reason(r).find("brake-order"), std::string::npos) << reason(r);
  r = set(*amp, {"NVBRAKEONV=30000"}, ValueSyntax::Raw);  // wpd NVBRAKEONV 30000: below BRAKEOFFV 340 V
  EXPECT_TRUE(refused(r));
  EXPECT_NE(reason(r).find("must be below"), std::string::npos) << reason(r);
  EXPECT_EQ(rig.truth().eeprom, before.eeprom) << "nothing was written";
}

TEST(OpsRules, UnderVoltageAboveOverVoltageIsRefused) {
  SimRig rig;
  auto amp = rig.open();
  const auto r = set(*amp, {"NVBUSUNDERV=390V"}, ValueSyntax::Engineering, {.force = true});
  EXPECT_TRUE(refused(r)) << "the manual's order, not a guard: --force does not lift it";
  EXPECT_NE(reason(r).find("undervoltage-below-overvoltage"), std::string::npos) << reason(r);
  EXPECT_EQ(rig.value("NVBUSUNDERV"), 3500);
}

TEST(OpsRules, LiveOverVoltageAtOrBelowTheMeasuredBusNeedsForce) {
  SimRig rig(RigOptions().bus(320));
  auto amp = rig.open();
  auto r = set(*amp, {"BUSOVERV=300V"});
  EXPECT_TRUE(refused(r));
  EXPECT_NE(reason(r).find("320.00 V the card measures"), std::string::npos) << reason(r);
  EXPECT_EQ(rig.value("BUSOVERV"), 38500);
  r = set(*amp, {"BUSOVERV=300V"}, ValueSyntax::Engineering, {.force = true});
  EXPECT_EQ(r.run.outcome, Outcome::Done) << reason(r);
  EXPECT_EQ(rig.value("BUSOVERV"), 30000);
}

TEST(OpsRules, AnOverlayCannotWidenTheCardsThirtyAmpRating) {
  SimRig rig(RigOptions().overlay("parameters:\n  - name: NVMAXCURRENT\n    max: 6000\n"));
  auto amp = rig.open();
  const auto r = set(*amp, {"NVMAXCURRENT=45A"});
  EXPECT_TRUE(refused(r));
  EXPECT_NE(reason(r).find("30 A"), std::string::npos) << reason(r);
  EXPECT_EQ(rig.value("NVMAXCURRENT"), 1000);
}

TEST(OpsRules, ThresholdsAreWrittenSoEveryStepKeepsTheirOrder) {
  SimRig rig(RigOptions().bus(160));
  auto amp = rig.open();
  // Given as ON first: written OFF first, or the card would hold 190/340 (inverted) between.
  const auto r = set(*amp, {"NVBRAKEONV=190V", "NVBRAKEOFFV=170V"});
  ASSERT_EQ(r.run.outcome, Outcome::Done) << reason(r);
  ASSERT_EQ(r.run.result->writes.size(), 2u);
  EXPECT_EQ(r.run.result->writes[0].cell, "NVBRAKEOFFV");
  EXPECT_EQ(rig.value("NVBRAKEONV"), 19000);
  EXPECT_EQ(rig.value("NVBRAKEOFFV"), 17000);
}

// ---------------------------------------------------------------- a reset inside the EEPROM sequence
// The card resets after the Nth command (instantly back, NV mode gone) at every point of a
// one-cell EEPROM write: no write may land in working memory and stay, NV mode is never left
// on, and what the tool says matches the EEPROM.
TEST(OpsResets, ResetAtAnyPointOfAnNvWriteLeavesNoStrayWriteAndTellsTheTruth) {
  std::size_t strays_cleared = 0;
  for (int n = 1; n <= 60; ++n) {
    for (const int reset_ms : {0, 1}) {
      SCOPED_TRACE("reset-after " + std::to_string(n) + ", reset time " + std::to_string(reset_ms) + " ms");
      SimRig rig(RigOptions().reset_ms(reset_ms));
      auto amp = rig.open();
      const auto before = rig.truth();
      rig.control("reset-after " + std::to_string(n));
      const auto r = set(*amp, {"NVMAXCURRENT=12A"});
      rig.control("reset-after off");
      const auto after = rig.truth();
      EXPECT_EQ(after.nv_access, lbp::local::NvAccess::Ram);
      EXPECT_FALSE(after.rpcmem);
      EXPECT_EQ(rig.unexplained_changes(before, after, {"NVMAXCURRENT"}), std::vector<std::string>{});
      const auto eeprom = rig.value("NVMAXCURRENT");
      if (r.run.outcome == Outcome::Done) {
        EXPECT_EQ(eeprom, 1200);
      }
      if (r.run.outcome == Outcome::RolledBack || r.run.outcome == Outcome::Failed) {
        EXPECT_EQ(eeprom, 1000);
      }
      if (r.run.outcome == Outcome::Uncertain) {
        EXPECT_FALSE(r.run.result->cells.empty()) << "name the cells";
      }
      for (const auto& e : r.run.result->events)
        strays_cleared += e.find("held the value meant for") != std::string::npos;
    }
  }
  // With an instant reset right after the mode check, the data write lands in working
  // memory: the sweep must have met that case, or it proves nothing about it.
  EXPECT_GT(strays_cleared, 0u);
}

TEST(OpsResets, ProfileApplyUnderResetsRestoresWithoutStrayWrites) {
  for (int n = 1; n <= 90; n += 2) {
    SCOPED_TRACE("reset-after " + std::to_string(n));
    SimRig rig(RigOptions().reset_ms(0).bus(160));
    auto amp = rig.open();
    const auto before = rig.truth();
    rig.control("reset-after " + std::to_string(n));
    const auto r = set(*amp, {"NVBRAKEONV=190V", "NVBRAKEOFFV=170V", "NVBUSOVERV=195V", "NVMAXCURRENT=12A"});
    rig.control("reset-after off");
    const auto after = rig.truth();
    EXPECT_EQ(after.nv_access, lbp::local::NvAccess::Ram);
    EXPECT_EQ(
        rig.unexplained_changes(before, after, {"NVBRAKEONV", "NVBRAKEOFFV", "NVBUSOVERV", "NVMAXCURRENT"}),
        std::vector<std::string>{});
    EXPECT_LT(rig.value("NVBRAKEOFFV"), rig.value("NVBRAKEONV")) << "never inverted";
    if (r.run.outcome == Outcome::RolledBack) {
      EXPECT_EQ(rig.value("NVBRAKEONV"), 36000);
      EXPECT_EQ(rig.value("NVMAXCURRENT"), 1000);
    }
    if (r.run.outcome == Outcome::Done) {
      EXPECT_EQ(rig.value("NVBRAKEONV"), 19000);
    }
  }
}

// ---------------------------------------------------------------- a card that stops answering
TEST(OpsMute, ACardThatGoesSilentMidWriteIsReportedCellByCellNeverInverted) {
  for (int n = 2; n <= 16; n += 2) {
    SCOPED_TRACE("mute-after " + std::to_string(n));
    SimRig rig(RigOptions().bus(160));
    auto amp = rig.open();
    rig.control("mute-after " + std::to_string(n));
    const auto r = set(*amp, {"NVBRAKEONV=190V", "NVBRAKEOFFV=170V"});
    rig.control("mute-after off");
    EXPECT_LT(rig.value("NVBRAKEOFFV"), rig.value("NVBRAKEONV"))
        << "every intermediate state keeps the order";
    const auto& res = *r.run.result;
    const auto on = rig.value("NVBRAKEONV"), off = rig.value("NVBRAKEOFFV");
    if (r.run.outcome == Outcome::Done) {
      EXPECT_TRUE(on == 19000 && off == 17000);
    }
    if (r.run.outcome == Outcome::Failed || r.run.outcome == Outcome::RolledBack) {
      EXPECT_TRUE(on == 36000 && off == 34000) << to_string(r.run.outcome) << ": " << res.reason;
    }
    // A card left in a mode is never reported without it (the mute also stopped the card
    // from acting on the command that leaves it).
    const auto truth = rig.truth();
    if (truth.nv_access != lbp::local::NvAccess::Ram || truth.rpcmem) {
      EXPECT_EQ(r.run.outcome, Outcome::Uncertain) << res.reason;
      EXPECT_NE(r.run.mode_left_on.find("may still be in it"), std::string::npos) << res.reason;
    }
    if (r.run.outcome == Outcome::Uncertain && res.writes.empty()) {
      // Nothing written, but the line died inside a mode it could not confirm it left.
      EXPECT_NE(res.reason.find("may still be in it"), std::string::npos) << res.reason;
    } else if (r.run.outcome == Outcome::Uncertain) {
      EXPECT_FALSE(res.cells.empty()) << "uncertain must name the cells: " << res.reason;
      for (const auto& c : res.cells)
        if (c.status == CellStatus::Original) {
          EXPECT_EQ(rig.value(c.cell), c.original) << c.cell;
        }
    }
    if (r.run.outcome == Outcome::Done) {
      EXPECT_EQ(res.writes.size(), 2u) << "verified only when every write was";
    }
  }
}

// ---------------------------------------------------------------- torn and lost EEPROM cells
TEST(OpsPowerLoss, ATornEepromCellIsNamedAndNotCalledRestored) {
  for (const char* mode : {"torn", "lost"}) {
    SCOPED_TRACE(mode);
    SimRig rig(RigOptions().bus(160));
    auto amp = rig.open();
    rig.control(std::string("eeprom-power-loss ") + mode);
    const auto r = set(*amp, {"NVBRAKEONV=190V", "NVBRAKEOFFV=170V"});
    EXPECT_EQ(r.run.outcome, Outcome::Uncertain) << r.run.result->reason;
    ASSERT_FALSE(r.run.result->cells.empty());
    EXPECT_EQ(r.run.result->cells.front().cell, "NVBRAKEOFFV");
    EXPECT_EQ(r.run.result->cells.front().status, CellStatus::Unknown);
    EXPECT_EQ(exit_code(r.run.outcome), 4);
  }
}

// ---------------------------------------------------------------- honest reads on unknown firmware
TEST(OpsHonestReads, FaultsOnUnknownFirmwareComeFromTheCardsOwnRpcTable) {
  SimRig rig(RigOptions().map(7).bus(24).enable_off());
  auto amp = rig.open();
  EXPECT_FALSE(amp->identity().info.working_map_confirmed);
  const auto r = read_fault_registers(*amp);
  EXPECT_EQ(r.fault, rig.value("FAULT"));
  EXPECT_NE(r.fault, 0) << "no enable and a 24 V bus: the card has faults, and the tool must say so";
  ASSERT_TRUE(r.busv_v);
  EXPECT_DOUBLE_EQ(*r.busv_v, 24.0);
  // BUSV by name: the card's address, not the database's guess.
  const auto busv = read_values(*amp, std::vector<std::string>{"BUSV"}).front();
  ASSERT_TRUE(busv.fact());
  EXPECT_EQ(*busv.raw, 2400);
  // A working parameter the card does not name is unknown, not a guess.
  const auto kqp = read_values(*amp, std::vector<std::string>{"KQP"}).front();
  EXPECT_FALSE(kqp.raw);
  EXPECT_NE(unknown_text(kqp).find("not confirmed for SWREVISION"), std::string::npos) << unknown_text(kqp);
  // FAULTMASK is in no RPC: masking is refused rather than judged on a guessed address.
  EXPECT_THROW(FaultMaskChange(amp->db(), "bus-under-voltage", true, {}).run_on(*amp), device::SafetyError);
}

TEST(OpsHonestReads, AFreshConnectionLeavesModesADeadSessionLeftOn) {
  SimRig rig;
  {
    auto amp = rig.open();
    amp->link().execute_one(lbp::set_nv_access(lbp::local::NvAccess::Eeprom));
    amp->link().execute_one(lbp::local_write(lbp::local::kSetRpcMemAccess, 1));
  }  // the session "dies" in both modes
  auto amp = rig.open();
  EXPECT_EQ(amp->identity().modes_left.size(), 2u);
  const auto t = rig.truth();
  EXPECT_EQ(t.nv_access, lbp::local::NvAccess::Ram);
  EXPECT_FALSE(t.rpcmem);
}

// ---------------------------------------------------------------- discover
TEST(OpsDiscover, TwinsWithEqualValuesAreAmbiguousAndTheOverlayLoadsBack) {
  SimRig rig(RigOptions().map(7).bus(24).enable_off());
  auto amp = rig.open();
  const auto dir = std::filesystem::temp_directory_path() / "i20-ops-discover";
  std::filesystem::create_directories(dir);
  DiscoverOptions o;
  o.scan.scan_begin = 0x0000;
  o.scan.scan_end = 0x1000;
  o.output = dir / "map.yaml";
  o.overwrite = true;
  o.generated_at = "test";
  const auto result = discover(*amp, rig.loaded(), o);
  for (const char* twin : {"KQP", "KDP", "KQI", "KDI", "KQIL", "KDIL"}) {
    const auto it = std::ranges::find(result.report.findings, std::string(twin), &device::Finding::name);
    ASSERT_NE(it, result.report.findings.end()) << twin;
    EXPECT_EQ(it->outcome, device::Search::Ambiguous)
        << twin << " holds the same value as its twin: " << it->detail;
  }
  // The overlay loads, and with it the faults are read where the card keeps them.
  auto loaded = rig.loaded();
  loaded.apply_overlay_file(result.written);
  const auto resolved = loaded.for_firmware(result.report.swrevision);
  EXPECT_TRUE(resolved.address_confirmed(resolved.get("BRAKEONV")));
  auto again = Amp::attach(std::make_unique<link::PipelinedLink>(std::make_unique<sim::SimStream>(),
                                                                 ops::timing::serial_link({}, {})),
                           parse_endpoint("sim"), loaded);
  (void)again;
  std::filesystem::remove_all(dir);
}

TEST(OpsDiscover, CtrlCStopsTheScan) {
  SimRig rig(RigOptions().map(7));
  std::atomic<bool> stop{false};
  auto amp = rig.open(Cancel(stop));
  DiscoverOptions o;
  o.scan.scan_begin = 0x0800;
  o.scan.scan_end = 0x2800;
  o.scan.reset_first = false;
  o.scan.progress = [&](std::size_t done, std::size_t) {
    if (done >= 512) stop = true;
  };
  o.output = std::filesystem::temp_directory_path() / "i20-ops-discover-cancelled.yaml";
  std::filesystem::remove(o.output);
  EXPECT_THROW(discover(*amp, rig.loaded(), o), device::Cancelled);
  EXPECT_FALSE(std::filesystem::exists(o.output)) << "nothing written after Ctrl-C";
}

// ---------------------------------------------------------------- Ctrl-C
TEST(OpsCancel, CtrlCBeforeTheFirstWriteWritesNothing) {
  SimRig rig;
  std::atomic<bool> stop{true};  // pressed while the card was being read
  auto amp = rig.open();
  const auto before = rig.truth();
  const auto r = set(*amp, {"NVBRAKEONV=370V"}, ValueSyntax::Engineering, {}, Cancel(stop));
  EXPECT_EQ(r.run.outcome, Outcome::Interrupted);
  EXPECT_EQ(exit_code(r.run.outcome), 130);
  EXPECT_EQ(rig.truth().eeprom, before.eeprom);
}

// ---------------------------------------------------------------- a card that comes back
// Issue 18: the 8I20 loses its logic power at the first write of a change and is back 200 ms
// later. The tool waits for it (the silence window), finds the write missing, writes it again
// and verifies it. A power cycle sets no new STATUS bit (EXTR is set from the first power-up
// on), so the tool tells it by a working twin of a cell it writes that changed meanwhile:
// KQP, reloaded from NVKQP, and says the card reset.
TEST(OpsSilence, APowerCycleInTheMiddleOfAChangeIsWaitedForAndReported) {
  SimRig rig;
  auto amp = rig.open();
  rig.control("set KQP " + std::to_string(rig.value("NVKQP") + 7));  // a working value not from the EEPROM
  const auto kqp_before = rig.value("KQP");
  // The power goes before the first batch that writes, and comes back when the tool asks the
  // silent card again (the next batch, sent after the lost one timed out): the event, not a
  // fixed 200 ms, so a loaded machine cannot move the power-on past the silence window.
  enum class Power { On, OffBeforeAWrite, Back } power = Power::On;
  rig.before_each_batch([&rig, &power](std::span<const lbp::Command> batch) {
    const bool writes = std::ranges::any_of(batch, [](const lbp::Command& c) {
      return lbp::kind_of(c.bytes.front()) == lbp::CommandKind::Data &&
             lbp::DataHeader::decode(c.bytes.front()).write;
    });
    if (power == Power::On && writes) {
      power = Power::OffBeforeAWrite;
      rig.control("power off");
    } else if (power == Power::OffBeforeAWrite) {
      power = Power::Back;
      rig.control("power on");
    }
  });
  const auto r = set(*amp, {"NVKQP=" + std::to_string(rig.value("NVKQP") + 1)}, ValueSyntax::Raw);
  ASSERT_EQ(power, Power::Back) << "the tool never asked the silent card again";
  EXPECT_EQ(r.run.outcome, Outcome::Done) << reason(r);
  EXPECT_NE(rig.value("KQP"), kqp_before) << "the power cycle reloaded KQP from the EEPROM";
  EXPECT_NE(r.run.card_reset.find("KQP"), std::string::npos)
      << "the reset went unreported: " << r.run.card_reset;
  EXPECT_GE(amp->silences_ended(), 1u);
}
