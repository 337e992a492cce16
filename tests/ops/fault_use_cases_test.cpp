// SPDX-License-Identifier: GPL-2.0-or-later
// The fault use cases as the front ends make them: refused when made, before any card is
// asked; run on the card, judged by the simulator's own register.
#include <gtest/gtest.h>

#include "faults/error.hpp"
#include "ops/faults.hpp"
#include "sim_rig.hpp"

using namespace i20::ops;
using namespace i20::ops::testing;

TEST(FaultMaskChange, AnUnmaskableBitIsRefusedWhenMadeWithNothingAsked) {
  SimRig rig;
  auto amp = rig.open();
  const auto before = rig.stats();
  EXPECT_THROW(FaultMaskChange(amp->db(), "watchdog", true, {}), i20::faults::NotMaskable);
  EXPECT_THROW(FaultMaskChange(amp->db(), "no-such-fault", true, {}), i20::faults::UnknownBit);
  EXPECT_EQ(rig.stats().commands_executed, before.commands_executed) << "a refusal asked the card";
}

TEST(FaultMaskChange, MasksOneBitKeepsTheRestAndReadsTheRegistersAfter) {
  SimRig rig;
  auto amp = rig.open();
  const FaultMaskChange mask(amp->db(), "bus-under-voltage", true, {});
  const auto m = mask.run_on(*amp);
  ASSERT_EQ(m.run.outcome, Outcome::Done) << (m.run.result ? m.run.result->reason : m.run.error);
  EXPECT_EQ(m.wanted, static_cast<std::uint16_t>(m.before & ~0x0100)) << "bit 8, BUS UNDER VOLTAGE, only";
  EXPECT_EQ(rig.value("FAULTMASK"), m.wanted) << "the card holds another mask than the one written";
  ASSERT_TRUE(m.after && m.after->faultmask);
  EXPECT_EQ(*m.after->faultmask, m.wanted) << "the registers read after are not the card's";
  // Already as asked: nothing to write, and still the registers.
  const auto again = mask.run_on(*amp);
  EXPECT_EQ(again.run.outcome, Outcome::NothingToDo);
  EXPECT_TRUE(again.after);
}
